"""Ray casting, fault synthesis and the oracle: the per-scan costs without any link."""

from __future__ import annotations

import numpy as np
import pytest

from harness.bench.workload import lab_workload, prepared_frames
from harness.faults.sensor import build_profile
from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.reference.scan_logic import analyse_message, status_text


def test_raytestbatch_floor(benchmark, captured_rays) -> None:
    """The PyBullet floor: one rayTestBatch of 360 beams, for every tick of approach_wall."""
    from harness.sim.bullet import pb

    sim, rays = captured_rays
    lidar, client = sim.lidar, sim.world.client

    def cast_all() -> None:
        for starts, ends in rays:
            pb.rayTestBatch(
                starts,
                ends,
                numThreads=1,
                collisionFilterMask=lidar.ray_mask,
                physicsClientId=client,
            )

    benchmark.extra_info["scans_per_round"] = len(rays)
    benchmark(cast_all)


def test_lidar_truth(benchmark, captured_rays) -> None:
    """LidarModel.truth: the floor plus the pose, the ray rotation and the hits to ranges."""
    sim, _ = captured_rays
    benchmark(sim.lidar.truth)


@pytest.mark.parametrize("profile", ["clean", "noisy", "harsh"])
def test_fault_emit(benchmark, truths, profile: str) -> None:
    """One scan through a fault profile (harsh: every random draw)."""
    faults = build_profile([profile])
    from harness.scenario.files import resolve_scenario

    spec = resolve_scenario("approach_wall").lidar_spec
    rng = np.random.default_rng(7)
    truth = truths[len(truths) // 2]
    benchmark(faults.emit, truth, spec, rng, stamp=1.0)


def test_synthesis_approach_wall(benchmark) -> None:
    """A whole approach_wall run of simulation and faults (world built outside the timing)."""
    workload = lab_workload(1, ("approach_wall",))

    def setup():
        context = prepared_frames(workload)
        return (context, context.__enter__()), {}

    def consume(context, frames) -> None:
        try:
            for _ in frames:
                pass
        finally:
            context.__exit__(None, None, None)

    benchmark.pedantic(consume, setup=setup, rounds=5)


def test_oracle_judge(benchmark, scans) -> None:
    """The oracle on one scan and the reference logic's answer to it."""
    oracle = Oracle(0.5)
    scan = scans[len(scans) // 2]
    report = analyse_message(scan, 0.5)
    answers = Answers(
        statuses=[Received(status_text(report), 0.001)],
        warnings=[Received(bool(report.warning), 0.001)] if report.warning is not None else [],
    )
    benchmark(oracle.judge, 1, 0.1, scan, answers)
