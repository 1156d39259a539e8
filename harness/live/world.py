"""The scenario's world driven by velocity commands instead of its motion script.

The robot rolls on its wheel motors and the physics steps at its fixed
240 Hz, so a wall stops it as a wall stops the real robot (the wheels
slip; nothing passes through). The LIDAR casts its rays on demand.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from harness.errors import ConfigError
from harness.live.drive import DriveLimits
from harness.scenario.files import (
    SCENARIO_SUFFIXES,
    load_scenario_file,
    resolve_scenario,
    shipped_scenarios,
)
from harness.scenario.schema import Scenario
from harness.sim.lidar import LidarModel
from harness.sim.motion import Pose, WheelDriver
from harness.sim.world import TIME_STEP, World

WORLDS = Path(__file__).with_name("worlds")  # worlds of the lab that no scenario has


def world_names() -> list[str]:
    """The worlds shipped for `sim` beside the scenarios' own."""
    return sorted(p.stem for p in WORLDS.iterdir() if p.suffix in SCENARIO_SUFFIXES)


def resolve_world(ref: str) -> Scenario:
    """A shipped world (``single_wall``), a shipped scenario's world, or a scenario file."""
    for suffix in SCENARIO_SUFFIXES:
        path = WORLDS / f"{ref}{suffix}"
        if "/" not in ref and path.is_file():
            return load_scenario_file(path)
    try:
        return resolve_scenario(ref)
    except ConfigError as err:
        if not str(err).startswith("unknown scenario"):
            raise
        shipped = ", ".join(s.name for s in shipped_scenarios())
        raise ConfigError(
            f"unknown world {ref[:100]!r} (worlds: {', '.join(world_names())}; the shipped "
            f"scenarios' worlds: {shipped}; or give a scenario .yaml path)"
        ) from None


class LiveWorld:
    """One scenario's world, its LIDAR and the robot's wheels, stepped by the caller."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.spec = scenario.lidar_spec
        self.world = World(scenario)
        try:
            self.lidar = LidarModel.for_world(self.world, self.spec)
            self.driver = WheelDriver(self.world, TIME_STEP)
        except BaseException:
            self.world.close()
            raise
        wheels = self.driver.wheels
        self.limits = DriveLimits(wheels.track)
        self.t = 0.0  # simulation time, s
        self._steps = 0
        self._velocity = (0.0, 0.0)

    def drive(self, linear: float, angular: float) -> tuple[float, float]:
        """Command a body velocity; returns what the wheels were told (within their limits)."""
        limited = self.limits.limit(linear, angular)
        self.driver.drive(*limited)
        return limited

    @property
    def steps(self) -> int:
        """Physics steps taken since t = 0."""
        return self._steps

    def advance(self, steps: int) -> None:
        """Step the physics `steps` fixed steps of TIME_STEP."""
        if steps <= 0:
            return
        before = self.pose()
        self.world.step(steps)
        self._steps += steps
        self.t = self._steps * TIME_STEP
        self._velocity = _body_velocity(before, self.pose(), steps * TIME_STEP)

    def pose(self) -> Pose:
        return self.driver.pose()

    def velocity(self) -> tuple[float, float]:
        """Body velocity over the last advance: forward m/s and yaw rate rad/s."""
        return self._velocity

    def truth(self) -> np.ndarray:
        """True range of each beam now (float64, m; inf where nothing is in range)."""
        return self.lidar.truth()

    def close(self) -> None:
        self.world.close()

    def __enter__(self) -> LiveWorld:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _body_velocity(before: Pose, after: Pose, seconds: float) -> tuple[float, float]:
    """Forward speed and yaw rate between two poses `seconds` apart."""
    dx, dy = after.x - before.x, after.y - before.y
    forward = dx * math.cos(before.yaw) + dy * math.sin(before.yaw)
    turned = math.remainder(after.yaw - before.yaw, 2.0 * math.pi)
    return forward / seconds, turned / seconds
