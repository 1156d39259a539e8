"""Generated variations of a scenario: the wall moved, the start moved, the speed scaled (pure).

A campaign (``sweep --vary``) tries a node at distances, poses and speeds no
shipped file has; each variation is checked as a file is, so a level that
makes no sense is a usage error before anything runs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from harness.errors import ConfigError
from harness.option_names import named
from harness.safe_text import shown
from harness.scenario.files import checked_scenario
from harness.scenario.footprint import Outline
from harness.scenario.schema import Model, Scenario

__all__ = ["VARIATIONS", "ahead_distance", "varied"]


#: Each generated factor: its unit, and what a level means.
VARIATIONS = {
    "start_dx": "m, added to the start pose's x",
    "start_dy": "m, added to the start pose's y",
    "start_dyaw": "rad, added to the start heading",
    "wall_distance": "m, distance from the robot's start, straight ahead, to the first wall, "
    "box or cylinder; every obstacle moves along the start heading to make it so",
    "speed": "x, multiplies every motion segment's linear and angular speed",
}
ORDER = tuple(VARIATIONS)  # applied in this order: the start pose before the wall distance
MAX_REACH_M = 1000.0  # farther than any scenario's world: nothing ahead
_HIT_M = 1e-6
_MAX_STEPS = 10_000


def ahead_distance(scenario: Scenario) -> float | None:
    """Metres from the start position along the start heading to the first wall, box or
    cylinder (model files are not measured); None when nothing is ahead."""
    start = scenario.robot.start
    outlines = [o.outline() for o in scenario.obstacles if not isinstance(o, Model)]
    return _march(outlines, (start.x, start.y), (math.cos(start.yaw), math.sin(start.yaw)))


def _march(outlines: list[Outline], origin: tuple[float, float], way: tuple[float, float]):
    """Sphere tracing: step by the distance to the nearest outline until one is touched."""
    if not outlines:
        return None
    travelled = 0.0
    for _ in range(_MAX_STEPS):
        point = (origin[0] + way[0] * travelled, origin[1] + way[1] * travelled)
        gap = min(-outline.contains(point) for outline in outlines)
        if gap <= _HIT_M:
            return travelled
        travelled += gap
        if travelled > MAX_REACH_M:
            return None
    return travelled  # grazing an edge for 10,000 steps: as good as touching it


def varied(scenario: Scenario, levels: Mapping[str, float]) -> Scenario:
    """`scenario` with each level applied, checked as a scenario file would be."""
    if not levels:
        return scenario
    data: dict[str, Any] = scenario.model_dump(mode="json")
    where = shown(scenario.source or scenario.name)
    start = data["robot"]["start"]
    for name in ORDER:
        if name not in levels:
            continue
        value = levels[name]
        if name == "speed":
            for segment in data["motion"]["segments"]:
                segment["linear"] *= value
                segment["angular"] *= value
        elif name in ("start_dx", "start_dy", "start_dyaw"):
            start[{"start_dx": "x", "start_dy": "y", "start_dyaw": "yaw"}[name]] += value
        else:
            _move_obstacles(data, scenario, value, where)
    label = " ".join(f"{n}={levels[n]:g}" for n in ORDER if n in levels)
    try:
        return checked_scenario(data, source=scenario.source or scenario.name)
    except ConfigError as err:
        raise ConfigError(f"{named('vary')} {label}: {err}") from None


def _move_obstacles(data: dict[str, Any], scenario: Scenario, distance: float, where: str):
    """Shift every obstacle along the start heading so the first ahead is `distance` away."""
    start = data["robot"]["start"]
    moved_start = scenario.robot.start.model_copy(update=start)
    robot = scenario.robot.model_copy(update={"start": moved_start})
    now = ahead_distance(scenario.model_copy(update={"robot": robot}))
    if now is None:
        raise ConfigError(
            f"{named('vary')} wall_distance: {where} has no wall, box or cylinder straight ahead "
            "of its start"
        )
    shift = distance - now
    dx, dy = shift * math.cos(start["yaw"]), shift * math.sin(start["yaw"])
    for obstacle in data["obstacles"]:
        for key in ("start", "end", "position"):
            if key in obstacle:
                point = obstacle[key]
                obstacle[key] = [point[0] + dx, point[1] + dy, *point[2:]]
