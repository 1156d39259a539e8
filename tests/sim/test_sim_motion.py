"""Pure motion logic: unicycle integration and segment bookkeeping (no pybullet)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from harness.errors import ConfigError
from harness.lidar.spec import PRESETS
from harness.scenario.ahead import ahead_mask
from harness.scenario.schema import Motion
from harness.sim.motion import (
    MotionScript,
    Piece,
    Pose,
    integrate,
    integrate_pieces,
    nearest_ahead,
    wheel_speeds,
)


def script(*segments: dict, source: str = "test.yaml") -> MotionScript:
    return MotionScript(Motion.model_validate({"segments": list(segments)}), source=source)


def run_time_only(s: MotionScript, dt: float, limit: int = 100000) -> list[Piece]:
    """Advance a script without obstacle conditions to its end."""
    pieces: list[Piece] = []
    for _ in range(limit):
        if s.done:
            return pieces
        pieces += s.advance(dt)
    raise AssertionError("script did not end")


def test_motion_module_does_not_import_pybullet():
    """The pure parts load without pybullet, so they test in milliseconds."""
    code = "import sys, harness.sim.motion; print('pybullet' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_straight_line_is_exact():
    """w = 0 moves v*dt along the heading."""
    end = integrate(Pose(1.0, 2.0, 0.3), 0.5, 0.0, 2.0)
    assert end.x == pytest.approx(1.0 + math.cos(0.3), abs=1e-12)
    assert end.y == pytest.approx(2.0 + math.sin(0.3), abs=1e-12)
    assert end.yaw == pytest.approx(0.3, abs=1e-15)


def test_arc_matches_the_closed_form_in_one_or_many_steps():
    """Constant (v, w) in one step or in 1000 gives the textbook arc."""
    v, w, t, yaw = 0.3, 0.7, 2.0, -0.4
    x = v / w * (math.sin(yaw + w * t) - math.sin(yaw))
    y = -v / w * (math.cos(yaw + w * t) - math.cos(yaw))
    one = integrate(Pose(0.0, 0.0, yaw), v, w, t)
    many = integrate_pieces(Pose(0.0, 0.0, yaw), [Piece(t / 1000, v, w)] * 1000)
    for pose in (one, many):
        assert (pose.x, pose.y) == pytest.approx((x, y), abs=1e-12)
        assert pose.yaw == pytest.approx(yaw + w * t, abs=1e-12)


def test_full_circle_returns_to_start():
    """A full turn of an arc ends where it began."""
    w = 0.9
    start = Pose(0.5, -0.2, 1.0)
    pieces = [Piece(2 * math.pi / w / 37, 0.25, w)] * 37
    end = integrate_pieces(start, pieces)
    assert (end.x, end.y, end.yaw) == pytest.approx((start.x, start.y, start.yaw), abs=1e-12)


def test_tiny_turn_rate_is_continuous_with_straight_motion():
    """The sinc form stays accurate as w -> 0 (no 0/0)."""
    straight = integrate(Pose(0, 0, 0.2), 1.0, 0.0, 1.0)
    tiny = integrate(Pose(0, 0, 0.2), 1.0, 1e-14, 1.0)
    assert (tiny.x, tiny.y) == pytest.approx((straight.x, straight.y), abs=1e-12)


def test_yaw_stays_wrapped():
    """Headings are reported in [-pi, pi]."""
    end = integrate(Pose(0, 0, 3.0), 0.0, 1.0, 1.0)
    assert end.yaw == pytest.approx(4.0 - 2 * math.pi)


def test_wheel_speeds_of_a_differential_drive():
    """Straight: equal; spin in place: opposite; rim speed = v -+ w*track/2."""
    assert wheel_speeds(0.2, 0.0, 0.05, 0.2) == pytest.approx((4.0, 4.0))
    assert wheel_speeds(0.0, 1.0, 0.05, 0.2) == pytest.approx((-2.0, 2.0))


def test_duration_segments_end_exactly_between_steps():
    """Segments end at their exact time even when that falls inside a step."""
    s = script(
        {"linear": 0.2, "until": {"duration": 1.0}},
        {"angular": 1.0, "until": {"duration": 0.5}},
    )
    pieces = run_time_only(s, 0.3)
    assert sum(p.duration for p in pieces if p.linear == 0.2) == pytest.approx(1.0, abs=1e-12)
    assert sum(p.duration for p in pieces if p.angular == 1.0) == pytest.approx(0.5, abs=1e-12)
    end = integrate_pieces(Pose(0, 0, 0), pieces)
    assert (end.x, end.y, end.yaw) == pytest.approx((0.2, 0.0, 0.5), abs=1e-12)


def test_distance_counts_path_length_either_way():
    """distance ends after |v| * t metres, forwards or backwards."""
    for v in (0.25, -0.25):
        end = integrate_pieces(
            Pose(0, 0, 0), run_time_only(script({"linear": v, "until": {"distance": 1.0}}), 0.1)
        )
        assert end.x == pytest.approx(math.copysign(1.0, v), abs=1e-12)


def test_turn_counts_absolute_radians():
    """turn ends after |w| * t radians, in either direction, along an arc too."""
    s = script({"linear": 0.1, "angular": -0.5, "until": {"turn": math.pi}})
    pieces = run_time_only(s, 0.1)
    assert sum(p.duration for p in pieces) == pytest.approx(2 * math.pi, abs=1e-12)
    end = integrate_pieces(Pose(0, 0, 0), pieces)
    assert abs(end.yaw) == pytest.approx(math.pi, abs=1e-12)
    assert (end.x, end.y) == pytest.approx((0.0, -0.4), abs=1e-12)  # half circle of r = 0.2


def test_distance_that_cannot_be_reached_is_a_config_error():
    """A distance at linear 0 (or too slow for its timeout) fails up front, naming the field."""
    with pytest.raises(
        ConfigError,
        match=r"^test\.yaml: motion\.segments\[1\]\.until: distance 1 m not reached within 60 s",
    ):
        script({"until": {"duration": 1}}, {"angular": 1.0, "until": {"distance": 1.0}})
    with pytest.raises(
        ConfigError, match=r"segments\[0\]\.until: turn 3 rad not reached within 2 s"
    ):
        script({"angular": 1.0, "until": {"turn": 3.0, "timeout": 2.0}})


def test_obstacle_below_ends_on_the_first_scan_under_the_limit():
    """obstacle_ahead_below holds until a scan reads strictly less."""
    s = script({"linear": 0.2, "until": {"obstacle_ahead_below": 0.3}})
    s.observe(1.0)
    assert s.advance(0.1) == [Piece(0.1, 0.2, 0.0)]
    s.observe(0.3)
    assert not s.done
    s.observe(0.29)
    assert s.done and s.advance(0.1) == []


def test_obstacle_above_ends_when_clear_and_inf_counts_as_clear():
    """obstacle_ahead_above ends on a farther reading, and nothing at all is farther."""
    s = script({"linear": -0.2, "until": {"obstacle_ahead_above": 0.5}})
    s.observe(0.4)
    assert not s.done
    s.observe(math.inf)
    assert s.done


def test_condition_already_true_takes_no_time():
    """A segment whose obstacle condition holds at its start is skipped on that scan."""
    s = script(
        {"linear": 0.2, "until": {"obstacle_ahead_below": 0.5}},
        {"linear": -0.1, "until": {"duration": 1.0}},
    )
    s.observe(0.4)
    assert s.index == 1 and s.command == (-0.1, 0.0)


def test_obstacle_condition_timeout_names_the_segment():
    """An obstacle condition not met within its timeout is a ConfigError naming it."""
    s = script(
        {"until": {"duration": 0.5}},
        {"linear": 0.1, "until": {"obstacle_ahead_below": 0.2, "timeout": 1.0}},
    )
    t = 0.0
    with pytest.raises(ConfigError) as err:
        while True:
            s.observe(2.0)
            s.advance(0.1)
            t += 0.1
    assert str(err.value) == (
        "test.yaml: motion.segments[1].until: obstacle_ahead_below 0.2 m not reached within 1 s"
    )
    assert t == pytest.approx(1.5)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_ahead_window_is_plus_minus_ten_degrees_of_forward(name):
    """The 'ahead' beams are those within +-10 deg of +x, whatever the layout."""
    spec = PRESETS[name]
    mask = ahead_mask(spec)
    angles = (
        np.remainder(
            spec.angle_min + np.arange(spec.samples) * spec.angle_increment + np.pi, 2 * np.pi
        )
        - np.pi
    )
    assert np.all(np.abs(angles[mask]) <= math.radians(10) + 1e-9)
    assert np.all(np.abs(angles[~mask]) > math.radians(10))
    assert mask.sum() >= 19
    truth = np.full(spec.samples, np.inf)
    assert nearest_ahead(truth, mask) == math.inf
    truth[np.argmin(np.abs(angles))] = 0.7
    truth[np.argmin(np.abs(angles - math.pi / 2))] = 0.1  # to the side: ignored
    assert nearest_ahead(truth, mask) == 0.7
