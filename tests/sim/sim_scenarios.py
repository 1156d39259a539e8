"""Building small valid scenarios for the simulator tests."""

from __future__ import annotations

from typing import Any

from harness.scenario.files import parse_scenario
from harness.scenario.schema import Scenario


def make_scenario(
    *,
    obstacles: list[dict[str, Any]] | None = None,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    lidar: dict[str, Any] | None = None,
    segments: list[dict[str, Any]] | None = None,
    mode: str = "kinematic",
    robot: dict[str, Any] | None = None,
    source: str = "test.yaml",
) -> Scenario:
    """A valid scenario from the few fields a test cares about."""
    x, y, yaw = start
    data = {
        "description": "simulator test",
        "robot": {**(robot or {}), "start": {"x": x, "y": y, "yaw": yaw}},
        "lidar": lidar or {"preset": "gazebo"},
        "obstacles": obstacles or [],
        "motion": {"mode": mode, "segments": segments or [{"until": {"duration": 0.1}}]},
    }
    return parse_scenario(data, source=source)
