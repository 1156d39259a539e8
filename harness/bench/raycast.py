"""Stage 'raycast': the PyBullet floor, ``rayTestBatch`` alone for the workload's scans.

Each scenario is simulated once, untimed, keeping every tick's rays and
robot pose; then, in the same world, the robot is put back at each pose
(untimed) and only ``LidarModel.cast`` (its ``rayTestBatch`` calls) is
timed. Nothing the harness adds around the call (pose lookup, ray
rotation, turning hits into ranges) is in this figure; the whole of
``LidarModel.truth`` is timed as well, as ``truth_ms``, so the difference
shows what the harness's own ray code costs.
"""

from __future__ import annotations

import time

import numpy as np

from harness.bench.stage import StageResult
from harness.bench.stats import median
from harness.bench.workload import Workload

ROUNDS = 3  # the floor is cheap: time every scan this many times, keep the median round


def measure_raycast(workload: Workload) -> StageResult:
    """Seconds of rayTestBatch per scan over the workload (the median of ROUNDS rounds)."""
    from harness.sim.bullet import pb
    from harness.sim.simulation import Simulation

    cast_s = truth_s = simulated = 0.0
    scans = 0
    for scenario in workload.runs():
        with Simulation(scenario) as sim:
            lidar, client, robot = sim.lidar, sim.world.client, sim.world.robot
            captured = []
            for tick in sim.ticks():
                starts, ends = lidar.rays()
                pose = pb.getBasePositionAndOrientation(robot, physicsClientId=client)
                captured.append((starts, ends, pose, tick.truth))
            simulated += len(captured) * sim.spec.scan_time
            scans += len(captured)
            cast_rounds, truth_rounds = [], []
            for _ in range(ROUNDS):
                round_cast = round_truth = 0.0
                for starts, ends, (position, orientation), truth in captured:
                    pb.resetBasePositionAndOrientation(
                        robot, position, orientation, physicsClientId=client
                    )
                    started = time.perf_counter()
                    hits = lidar.cast(starts, ends)
                    round_cast += time.perf_counter() - started
                    started = time.perf_counter()
                    again = lidar.truth()
                    round_truth += time.perf_counter() - started
                    _check_same(hits, truth, lidar.spec.range_max)
                    # The pose put back may differ in the last bits (a quaternion
                    # renormalised): hits may move by nanometres, not more.
                    if not np.allclose(again, truth, rtol=0.0, atol=1e-6):
                        raise RuntimeError("ray casting is not repeatable: the floor is unsound")
                cast_rounds.append(round_cast)
                truth_rounds.append(round_truth)
            cast_s += median(cast_rounds)
            truth_s += median(truth_rounds)
    extra = {"truth_ms": truth_s / scans * 1000.0, "rounds": ROUNDS}
    return StageResult("raycast", scans, cast_s, simulated, extra=extra)


def _check_same(hits: list, truth: np.ndarray, range_max: float) -> None:
    """The timed call saw what the simulation saw (else the floor measures other scans)."""
    got = np.array([h[2] if h[0] >= 0 else np.inf for h in hits]) * range_max
    if not np.array_equal(got, truth):
        raise RuntimeError("re-cast rays differ from the simulated scan: the floor is unsound")
