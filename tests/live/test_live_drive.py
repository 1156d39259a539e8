"""What a /cmd_vel becomes on the wheels, and when the robot stops (pure)."""

from __future__ import annotations

import math

import pytest

from harness.live.drive import CommandWatchdog, DriveLimits

V2 = DriveLimits(track=0.1866, top_speed=0.4)


def test_a_command_within_the_wheels_passes_unchanged() -> None:
    assert V2.limit(0.2, 0.5) == (0.2, 0.5)


@pytest.mark.parametrize("linear, angular", [(1.0, 0.0), (0.5, 3.0), (-2.0, -1.0), (0.0, 10.0)])
def test_a_command_beyond_the_wheels_keeps_its_curvature(linear: float, angular: float) -> None:
    v, w = V2.limit(linear, angular)
    left, right = v - w * V2.track / 2, v + w * V2.track / 2
    assert max(abs(left), abs(right)) == pytest.approx(V2.top_speed)
    if linear:
        assert w / v == pytest.approx(angular / linear)
    assert math.copysign(1, v) == math.copysign(1, linear) or linear == 0


def test_spinning_on_the_spot_is_limited_by_the_track() -> None:
    assert V2.top_turn == pytest.approx(2 * 0.4 / 0.1866)
    assert V2.limit(0.0, 100.0) == pytest.approx((0.0, V2.top_turn))


def test_not_finite_parts_count_as_zero() -> None:
    assert V2.limit(math.nan, math.inf) == (0.0, 0.0)


def test_the_robot_stops_when_commands_stop_coming() -> None:
    watchdog = CommandWatchdog(timeout=0.5)
    assert watchdog.command(0.0) == (0.0, 0.0)  # nothing heard yet
    watchdog.heard(0.3, 0.1, now=10.0)
    assert watchdog.command(10.4) == (0.3, 0.1)
    assert watchdog.command(10.6) == (0.0, 0.0)
    watchdog.heard(-0.1, 0.0, now=11.0)
    assert watchdog.command(11.2) == (-0.1, 0.0)
