"""The Simulation the runner drives: ticks, motion scripts, determinism, wheels."""

from __future__ import annotations

import hashlib
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from sim_scenarios import make_scenario

from harness.errors import ConfigError
from harness.scenario.ahead import ahead_mask
from harness.scenario.files import parse_scenario
from harness.sim import SimTick, Simulation
from harness.sim.motion import nearest_ahead

WALL_AT_2 = {"type": "wall", "start": [2.0, -2.0], "end": [2.0, 2.0], "thickness": 0.1}
CLUTTER = [
    WALL_AT_2,
    {"type": "box", "position": [1.0, 1.0], "size": [0.3, 0.3, 0.3], "yaw": 0.4},
    {"type": "cylinder", "position": [0.5, -0.8], "radius": 0.12},
]


def run(scenario) -> list[SimTick]:
    with Simulation(scenario) as sim:
        return list(sim.ticks())


def ahead_of(tick: SimTick, spec) -> float:
    return nearest_ahead(tick.truth, ahead_mask(spec))


def test_duration_ticks_from_zero_to_the_end_pose():
    """A 1 s script at 10 Hz gives ticks at t = 0.0 .. 1.0, the last at the end pose."""
    scenario = make_scenario(
        start=(0.5, 0.0, 0.0), segments=[{"linear": 0.2, "until": {"duration": 1.0}}]
    )
    ticks = run(scenario)
    assert [t.tick for t in ticks] == list(range(11))
    assert [t.t for t in ticks] == [k * 0.1 for k in range(11)]
    assert ticks[0].x == 0.5 and ticks[-1].x == pytest.approx(0.7, abs=1e-12)
    assert all(t.truth.dtype == np.float64 and t.truth.shape == (360,) for t in ticks)


def test_script_ending_between_scans_is_followed_by_one_scan_at_rest():
    """At 5.5 Hz a 1 s script ends between scans; the next scan sees the end pose."""
    scenario = make_scenario(
        lidar={"preset": "rplidar_a1"},
        segments=[{"linear": 0.2, "until": {"duration": 1.0}}],
    )
    ticks = run(scenario)
    assert len(ticks) == 7 and ticks[-1].t == pytest.approx(6 / 5.5)
    assert ticks[-2].x == pytest.approx(0.2 * 5 / 5.5, abs=1e-12)
    assert ticks[-1].x == pytest.approx(0.2, abs=1e-12)


def test_turn_then_distance_lands_exactly():
    """Kinematic mode is exact: turn 90 deg, drive 0.5 m, end at (0, 0.5) facing +y."""
    scenario = make_scenario(
        segments=[
            {"angular": 0.7, "until": {"turn": math.pi / 2}},
            {"linear": 0.3, "until": {"distance": 0.5}},
        ]
    )
    end = run(scenario)[-1]
    assert (end.x, end.y, end.yaw) == pytest.approx((0.0, 0.5, math.pi / 2), abs=1e-12)


def test_truth_moves_with_the_robot():
    """Driving at a wall shortens the range ahead by the distance driven each scan."""
    scenario = make_scenario(
        obstacles=[WALL_AT_2], segments=[{"linear": 0.2, "until": {"duration": 1.0}}]
    )
    ticks = run(scenario)
    spec = scenario.lidar_spec
    for tick in ticks:
        assert ahead_of(tick, spec) == pytest.approx(1.95 + 0.016 - tick.x, abs=1e-3)


def test_obstacle_ahead_below_stops_on_the_first_close_scan():
    """The script ends on the first scan closer than the limit; that scan is the last tick."""
    scenario = make_scenario(
        obstacles=[WALL_AT_2],
        segments=[{"linear": 0.25, "until": {"obstacle_ahead_below": 0.3}}],
    )
    ticks = run(scenario)
    spec = scenario.lidar_spec
    assert ahead_of(ticks[-1], spec) < 0.3
    assert all(ahead_of(t, spec) >= 0.3 for t in ticks[:-1])
    assert ticks[-1].x == pytest.approx(ticks[-2].x + 0.025, abs=1e-12)


def test_obstacle_ahead_above_backs_away_until_clear():
    """Reversing until the range ahead exceeds the limit; a condition true at once takes no time."""
    scenario = make_scenario(
        obstacles=[WALL_AT_2],
        start=(1.6, 0.0, 0.0),
        segments=[
            {"linear": 0.2, "until": {"obstacle_ahead_below": 1.0}},  # already true at t = 0
            {"linear": -0.2, "until": {"obstacle_ahead_above": 0.8}},
        ],
    )
    ticks = run(scenario)
    spec = scenario.lidar_spec
    assert ticks[1].x < ticks[0].x  # no forward step: the first segment took no time
    assert ahead_of(ticks[-1], spec) > 0.8
    assert all(ahead_of(t, spec) <= 0.8 for t in ticks[:-1])


def test_unreached_obstacle_condition_raises_after_its_timeout():
    """Standing still while waiting for a wall is a ConfigError naming the segment."""
    scenario = make_scenario(
        obstacles=[WALL_AT_2],
        segments=[
            {"linear": 0.2, "until": {"duration": 0.2}},
            {"until": {"obstacle_ahead_below": 0.2, "timeout": 1.0}},
        ],
    )
    seen = []
    with pytest.raises(ConfigError) as err, Simulation(scenario) as sim:
        for tick in sim.ticks():
            seen.append(tick.t)
    assert str(err.value) == (
        "test.yaml: motion.segments[1].until: obstacle_ahead_below 0.2 m not reached within 1 s"
    )
    assert seen[-1] == pytest.approx(1.1)


def test_unreachable_distance_fails_before_building_the_world():
    """A distance at zero speed is refused when the Simulation is built."""
    scenario = make_scenario(segments=[{"angular": 0.5, "until": {"distance": 1.0}}])
    with pytest.raises(ConfigError, match=r"^test\.yaml: motion\.segments\[0\]\.until: distance"):
        Simulation(scenario)


def test_ticks_runs_once():
    """A Simulation is one run; a second pass is a programming error."""
    with Simulation(make_scenario()) as sim:
        list(sim.ticks())
        with pytest.raises(RuntimeError):
            list(sim.ticks())


@pytest.mark.parametrize("mode", ["kinematic", "wheels"])
def test_same_scenario_gives_byte_identical_truth(mode):
    """Two runs of one scenario in one process produce the same bytes, poses and all."""
    scenario = make_scenario(
        obstacles=CLUTTER,
        start=(-0.5, 0.1, 0.2),
        mode=mode,
        segments=[
            {"linear": 0.2, "angular": 0.3, "until": {"duration": 1.5}},
            {"linear": 0.15, "until": {"obstacle_ahead_below": 0.6}},
        ],
    )
    a, b = run(scenario), run(scenario)
    assert len(a) == len(b) > 5
    for ta, tb in zip(a, b, strict=True):
        assert ta.truth.tobytes() == tb.truth.tobytes()
        assert (ta.t, ta.x, ta.y, ta.yaw) == (tb.t, tb.x, tb.y, tb.yaw)


_DIGEST = """
import hashlib, json, sys
from harness.scenario.files import parse_scenario
from harness.sim import Simulation
with Simulation(parse_scenario(json.loads(sys.argv[1]), source="test.yaml")) as sim:
    h = hashlib.sha256()
    for tick in sim.ticks():
        h.update(tick.truth.tobytes())
print(h.hexdigest())
"""


def test_truth_is_identical_across_processes():
    """A fresh process reproduces the same scans, byte for byte (wheels mode, the hard case)."""
    data = {
        "description": "determinism across processes",
        "obstacles": CLUTTER,
        "motion": {
            "mode": "wheels",
            "segments": [{"linear": 0.2, "angular": -0.4, "until": {"duration": 1.0}}],
        },
    }
    with Simulation(parse_scenario(data, source="test.yaml")) as sim:
        here = hashlib.sha256(b"".join(t.truth.tobytes() for t in sim.ticks())).hexdigest()
    out = subprocess.run(
        [sys.executable, "-c", _DIGEST, json.dumps(data)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.strip().splitlines()[-1] == here


def test_wheels_mode_drives_roughly_as_commanded():
    """Wheel motors move the robot within a few % of the commanded line and turn."""
    straight = run(
        make_scenario(mode="wheels", segments=[{"linear": 0.2, "until": {"duration": 2.0}}])
    )[-1]
    assert straight.x == pytest.approx(0.4, rel=0.03)
    assert abs(straight.y) < 0.01 and abs(straight.yaw) < 0.02
    spin = run(
        make_scenario(mode="wheels", segments=[{"angular": 1.0, "until": {"turn": math.pi / 2}}])
    )[-1]
    assert spin.yaw == pytest.approx(math.pi / 2, rel=0.03)
    assert math.hypot(spin.x, spin.y) < 0.01
    back = run(
        make_scenario(mode="wheels", segments=[{"linear": -0.1, "until": {"distance": 0.3}}])
    )[-1]
    assert back.x == pytest.approx(-0.3, rel=0.03)


def test_wheels_mode_needs_wheel_joints(tmp_path):
    """A URDF without the wheel joints cannot run in wheels mode: the error says why."""
    (tmp_path / "plain.urdf").write_text(
        '<?xml version="1.0"?><robot name="p"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>'
        "</link></robot>"
    )
    scenario = make_scenario(
        robot={"urdf": "plain.urdf", "lidar_link": "base"},
        mode="wheels",
        source=str(tmp_path / "s.yaml"),
    )
    with pytest.raises(
        ConfigError, match=r"s\.yaml: motion\.mode: no joint named 'left_wheel_joint'"
    ):
        Simulation(scenario)
