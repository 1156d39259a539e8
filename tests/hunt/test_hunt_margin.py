"""A run's margin and way of failing, read from real runs of hunt scenarios through the
inprocess link (processing functions as students write them; no ROS)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.hunt.margin import FAILED, Assessment, failure_kinds
from harness.hunt.space import Candidate, placed, robot_footprint
from harness.hunt.task import run_candidate
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

STUDENTS = Path(__file__).resolve().parents[1] / "student_functions.py"
ROBOT = robot_footprint()


def assessed(candidate: Candidate, function: str | None = None) -> Assessment:
    """The hunt task's assessment of `candidate` run through `function` (the reference
    solution when None)."""
    options = LinkOptions(processor=f"{STUDENTS}:{function}" if function else None)
    outcome = run_candidate(placed(candidate, ROBOT), 0, "inprocess", options, RunSettings())
    assert outcome.assessment is not None, outcome.problem
    return outcome.assessment


def test_a_correct_answer_far_from_every_edge_has_a_large_margin() -> None:
    wall = Candidate(obstacle="wall", distance=2.0, size=2.0, threshold=0.5)
    result = assessed(wall)
    assert not result.failed and result.kinds == () and result.ticks >= 1
    assert 0.6 < result.margin <= 1.0


def test_the_margin_shrinks_as_the_nearest_return_nears_the_threshold() -> None:
    margins = [
        assessed(Candidate(obstacle="wall", distance=d, size=20.0, threshold=0.5)).margin
        for d in (3.0, 1.0, 0.6, 0.52)
    ]
    assert margins == sorted(margins, reverse=True)
    assert margins[0] - margins[-1] > 0.2


def test_nothing_in_range_is_an_edge_too() -> None:
    nothing = assessed(Candidate(obstacle="none"))
    lots = assessed(Candidate(obstacle="wall", distance=2.0, size=4.0))
    assert not nothing.failed and nothing.margin < lots.margin


@pytest.mark.parametrize(
    ("function", "candidate", "kinds"),
    [
        ("angle_without_angle_min", Candidate(obstacle="wall", distance=1.0), ("angle",)),
        ("crash_when_nothing_in_range", Candidate(), ("error",)),
        (
            "threshold_hard_coded",
            Candidate(obstacle="wall", distance=0.7, size=2.0, threshold=1.0),
            ("warning",),
        ),
    ],
)
def test_a_failure_says_how_it_failed(function: str, candidate: Candidate, kinds) -> None:
    result = assessed(candidate, function)
    assert result.failed and result.margin == FAILED
    assert result.kinds == kinds
    assert result.first_failure and not result.first_failure.startswith("hunt candidate")


def test_failure_kinds_from_the_oracles_words() -> None:
    assert failure_kinds(["expected warning True; got False"]) == ("warning",)
    assert failure_kinds(
        ["status 'x' claims an obstacle at 0.00 m", "expected warning False (or none); got True"]
    ) == ("phantom obstacle", "warning")
    assert failure_kinds(["no status within 1 s"]) == ("answer",)
