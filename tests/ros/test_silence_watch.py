"""How the ros2 link names three missed deadlines in a row: slow, or stopped.

A slow node whose last answer had not come when the harness stopped waiting
(a loaded machine held it back past the catch-up wait) is still slow, not
stopped: its earlier answers came, late.
"""

from __future__ import annotations

import pytest

from harness.judge.answers import Answers, Received
from harness.links.base import LinkOptions
from harness.links.ros2 import Ros2Link

pytestmark = pytest.mark.ros

STATUS = "Min distance: 1.946 m, angle: -0.009 rad"


def missed(tick: int, late_after: float | None) -> Answers:
    """A scan's answers that missed the deadline; its own status came `late_after` s on."""
    late = [] if late_after is None else [Received(STATUS, late_after, tick=tick)]
    return Answers(timed_out=True, late=late)


def ending(late_afters: list[float | None]) -> str | None:
    link = Ros2Link(LinkOptions(scan_timeout=0.5))
    answers = Answers()
    for tick, after in enumerate(late_afters, start=1):
        answers = missed(tick, after)
        link._watch_silence(answers, tick)
    return answers.problem


def test_three_late_answers_are_too_late() -> None:
    assert ending([1.5, 1.5, 1.5]) == (
        "node answers too late: 3 scans in a row missed the 0.5 s deadline "
        "(the last answer came after 1.50 s)"
    )


def test_late_answers_then_one_not_yet_come_are_too_late_not_stopped() -> None:
    assert ending([1.5, 1.6, None]) == (
        "node answers too late: 3 scans in a row missed the 0.5 s deadline "
        "(tick 2's answer came after 1.60 s; the last scan's had not come when the harness "
        "stopped waiting)"
    )


def test_no_answer_at_all_is_stopped() -> None:
    problem = ending([None, None, None])
    assert problem is not None
    assert problem.startswith("node stopped answering: no status on /lidar_status for 3 scans")


def test_an_answer_in_time_starts_the_count_again() -> None:
    link = Ros2Link(LinkOptions(scan_timeout=0.5))
    link._watch_silence(missed(1, 1.5), 1)
    link._watch_silence(Answers(statuses=[Received(STATUS, 0.1)]), 2)
    answers = Answers()
    for tick in (3, 4, 5):
        answers = missed(tick, None)
        link._watch_silence(answers, tick)
    assert answers.problem is not None and answers.problem.startswith("node stopped answering")
