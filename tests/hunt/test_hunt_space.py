"""The hunt's space: candidates drawn by a real optuna trial, the scenario files they make,
the robot kept clear of its obstacle (pure, no ROS)."""

from __future__ import annotations

import math
from dataclasses import replace

import optuna
import pytest

from harness.hunt.space import (
    Candidate,
    clear_duration,
    fault_entries,
    obstacle_outline,
    placed,
    robot_footprint,
    scenario_document,
    suggest,
)
from harness.scenario.files import checked_scenario
from harness.scenario.footprint import overlap

ROBOT = robot_footprint()
EVERY_KIND = [
    Candidate(obstacle=o, motion=m, preset=p, convention=c, fault=f)
    for o, m, p, c, f in zip(
        ("none", "wall", "box", "cylinder", "wall"),
        ("still", "straight", "reverse", "turn", "straight"),
        ("gazebo", "rplidar_a1", "gazebo", "rplidar_a1", "gazebo"),
        ("rep117", "zero", "nan", "rep117", "zero"),
        ("none", "noise", "dropouts", "spurious", "far_returns"),
        strict=True,
    )
]


def test_a_trial_is_asked_only_for_the_numbers_that_apply() -> None:
    """No obstacle: no distance, bearing or size asked; standing: no speed; no fault: no
    rate (the optimiser learns nothing false about them)."""
    params = {
        "obstacle": "none",
        "motion": "still",
        "preset": "rplidar_a1",
        "convention": "nan",
        "fault": "none",
        "duration": 0.7,
        "threshold": 0.9,
    }
    candidate = suggest(optuna.trial.FixedTrial(params))
    assert candidate.preset == "rplidar_a1" and candidate.convention == "nan"
    assert candidate.duration == 0.7 and candidate.threshold == 0.9
    with pytest.raises(ValueError, match="distance"):  # FixedTrial: asked for what it lacks
        suggest(optuna.trial.FixedTrial({**params, "obstacle": "wall"}))


@pytest.mark.parametrize("candidate", EVERY_KIND, ids=lambda c: f"{c.obstacle}-{c.motion}")
def test_every_kind_of_candidate_makes_a_valid_scenario(candidate: Candidate) -> None:
    """Parsed and checked as a file from disk is (schema, reach, a start clear of the
    obstacle)."""
    candidate = placed(replace(candidate, distance=0.8, bearing=0.4, size=0.6), ROBOT)
    document = scenario_document(candidate, ROBOT, description="test", seed=3)
    scenario = checked_scenario(document, source="test")
    assert scenario.seed == 3 and scenario.lidar.preset == candidate.preset
    assert len(scenario.obstacles) == (candidate.obstacle != "none")
    assert len(scenario.motion.segments) == 1


def test_an_obstacle_drawn_inside_the_robot_is_pushed_out_along_its_bearing() -> None:
    inside = Candidate(obstacle="box", distance=0.05, bearing=2.0, size=0.3)
    moved = placed(inside, ROBOT)
    assert moved.distance > inside.distance and moved.bearing == inside.bearing
    outline = obstacle_outline(moved)
    assert outline is not None
    assert max(overlap(part, outline) for part in ROBOT) < 0
    checked_scenario(scenario_document(moved, ROBOT, description="t"), source="t")


@pytest.mark.parametrize("motion", ["straight", "reverse", "turn"])
def test_motion_stops_short_of_the_obstacle(motion: str) -> None:
    """Driving or turning into a wall is cut where the robot's outline would come within
    3 cm of it: a generated scenario is one a real robot could drive."""
    bearing = math.pi if motion == "reverse" else 0.0
    if motion == "turn":  # a long box beside the robot, which a turn would sweep into
        candidate = Candidate(obstacle="box", distance=0.09, bearing=math.pi / 2, size=0.5)
    else:
        candidate = Candidate(obstacle="wall", distance=0.6, bearing=bearing, size=2.0)
    candidate = placed(replace(candidate, motion=motion, speed=0.5, duration=3.0), ROBOT)
    allowed = clear_duration(candidate, ROBOT)
    assert allowed < candidate.duration
    segment = scenario_document(candidate, ROBOT, description="t")["motion"]["segments"][0]
    assert segment["until"]["duration"] <= max(allowed, 0.1) + 1e-9


def test_away_from_the_obstacle_the_motion_keeps_its_duration() -> None:
    candidate = Candidate(obstacle="wall", distance=1.0, bearing=0.0, motion="reverse")
    candidate = replace(candidate, speed=0.2, duration=2.0)
    assert clear_duration(candidate, ROBOT) == 2.0


def test_faults_and_conventions_in_the_scenario_file() -> None:
    assert fault_entries(Candidate()) == []
    assert fault_entries(Candidate(convention="zero")) == ["driver_zero"]
    noisy = fault_entries(Candidate(convention="nan", fault="noise", fault_rate=0.1))
    assert noisy == ["driver_nan", {"type": "noise", "sigma": 0.01}]
    assert fault_entries(Candidate(fault="spurious", fault_rate=0.05)) == [
        {"type": "spurious", "rate": 0.05}
    ]
    plain = scenario_document(Candidate(), ROBOT, description="t")
    assert "faults" not in plain and "obstacles" not in plain  # the simplest file


def test_a_description_says_what_the_scenario_does() -> None:
    text = Candidate(obstacle="wall", distance=0.5, convention="zero", fault="noise").describe()
    assert "wall" in text and "0.5 m" in text and "0.0" in text and "noise" in text
