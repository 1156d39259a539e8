"""Generated scenario variations: the wall moved, the start moved, the speed scaled (pure),
each checked as a scenario file is."""

from __future__ import annotations

import math

import pytest

from harness.errors import ConfigError
from harness.scenario.files import parse_scenario, resolve_scenario
from harness.scenario.variations import ahead_distance, varied


def test_the_wall_ahead_is_measured_and_moved() -> None:
    wall = resolve_scenario("approach_wall")
    before = ahead_distance(wall)
    assert before is not None and 0.5 < before < 5
    for distance in (0.4, 1.0, 3.0):
        moved = varied(wall, {"wall_distance": distance})
        assert ahead_distance(moved) == pytest.approx(distance, abs=1e-6)
        assert moved.name == wall.name and moved.source == wall.source
    assert ahead_distance(wall) == before  # the original is untouched


def test_the_start_heading_decides_what_is_ahead() -> None:
    """Turned 90 degrees, the wall is no longer ahead; a box at an angle is reached."""
    scenario = parse_scenario(
        {
            "description": "a box ahead and to the left",
            "obstacles": [{"type": "box", "position": [2.0, 2.0], "size": [1.0, 1.0, 0.5]}],
            "motion": {"segments": [{"linear": 0.1, "until": {"duration": 1.0}}]},
        }
    )
    assert ahead_distance(scenario) is None
    turned = varied(scenario, {"start_dyaw": math.pi / 4})
    assert ahead_distance(turned) == pytest.approx(math.hypot(1.5, 1.5), abs=1e-3)
    closer = varied(scenario, {"start_dyaw": math.pi / 4, "wall_distance": 0.5})
    assert ahead_distance(closer) == pytest.approx(0.5, abs=1e-6)


def test_start_offsets_and_speed() -> None:
    wall = resolve_scenario("approach_wall")
    moved = varied(wall, {"start_dx": 0.25, "start_dy": -0.5, "speed": 2.0})
    assert (moved.robot.start.x, moved.robot.start.y) == (0.25, -0.5)
    assert [s.linear for s in moved.motion.segments] == [
        2.0 * s.linear for s in wall.motion.segments
    ]
    assert varied(wall, {}) is wall


@pytest.mark.parametrize(
    ("scenario", "levels", "message"),
    [
        ("approach_wall", {"wall_distance": 0.01}, "--vary wall_distance=0.01: .* overlaps"),
        ("approach_wall", {"speed": 100.0}, "--vary speed=100: .*linear"),
        ("reverse_to_wall", {"wall_distance": 1.0}, "no wall, box or cylinder straight ahead"),
    ],
)
def test_a_level_that_makes_no_sense_is_a_usage_error(
    scenario: str, levels: dict[str, float], message: str
) -> None:
    with pytest.raises(ConfigError, match=message):
        varied(resolve_scenario(scenario), levels)
