"""One scripted run: the world, its LIDAR and the motion script, tick by tick.

This is the simulator's whole surface for the runner: build a
``Simulation`` from a scenario and iterate ``ticks()``; each tick is one
LIDAR revolution with the robot's pose and the true ranges at that moment.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from harness.lidar.spec import LidarSpec
from harness.scenario.ahead import ahead_mask
from harness.scenario.schema import Scenario
from harness.sim.lidar import LidarModel
from harness.sim.motion import KinematicDriver, MotionScript, Pose, WheelDriver, nearest_ahead
from harness.sim.world import TIME_STEP, World


@dataclass(frozen=True)
class SimTick:
    """One LIDAR revolution: when, where the robot was, and what is really there."""

    tick: int  # 0, 1, 2, ...
    t: float  # simulation time of this scan, s (= tick * spec.scan_time at a steady rate)
    x: float  # robot base pose at this scan: m, m, rad
    y: float
    yaw: float
    truth: np.ndarray  # float64 ranges from LidarModel.truth()
    period: float = 0.0  # seconds from this scan to the next (the revolution's scan_time)


class Simulation:
    """The scenario's world, stepped one LIDAR revolution at a time."""

    def __init__(self, scenario: Scenario, *, gui: bool = False) -> None:
        self.scenario = scenario
        self.spec: LidarSpec = scenario.lidar_spec
        self._script = MotionScript(scenario.motion, source=scenario.source)  # fails fast
        self._ahead = ahead_mask(self.spec)
        self._started = False
        self.world = World(scenario, gui=gui)
        try:
            self.lidar = LidarModel.for_world(self.world, self.spec)
            start = scenario.robot.start
            if scenario.motion.mode == "wheels":
                self._driver: KinematicDriver | WheelDriver = WheelDriver(self.world, TIME_STEP)
            else:
                self._driver = KinematicDriver(self.world, Pose(start.x, start.y, start.yaw))
        except BaseException:
            self.world.close()
            raise

    def ticks(self, periods: Iterator[float] | None = None) -> Iterator[SimTick]:
        """One tick per revolution from t = 0 until the script ends, end pose included; runs
        once. `periods`: the time from each scan to the next, for a LIDAR whose rate drifts
        (default: the spec's scan_time)."""
        if self._started:
            raise RuntimeError("Simulation.ticks() runs once; build a new Simulation")
        self._started = True
        scan_time = self.spec.scan_time
        tick, t = 0, 0.0
        while True:
            period = next(periods) if periods is not None else scan_time
            pose = self._driver.pose()
            truth = self.lidar.truth()
            self._script.observe(nearest_ahead(truth, self._ahead))
            yield SimTick(tick, t, pose.x, pose.y, pose.yaw, truth, period)
            if self._script.done:
                return
            tick += 1
            # A steady rate keeps tick * scan_time exactly, as before drift existed.
            t = tick * scan_time if periods is None else t + period
            self._driver.run_until(self._script, t)

    def close(self) -> None:
        """Release the physics client (idempotent)."""
        self.world.close()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
