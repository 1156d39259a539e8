"""The watchdogs over a node's answers, fed counts alone (no ROS graph, no node).

Silence: three missed deadlines in a row name the node slow (its answers came,
late), stopped, or silent when nothing is in range. Flood: far more than one
message a scan, at a rate no timer during long waits reaches. Strangers:
several answers to one scan because another node shares the domain.
"""

from __future__ import annotations

from harness.judge.answers import Answers, Received
from harness.links.watchdogs import (
    FLOOD_MIN,
    FLOOD_SCANS,
    STOPPED_AFTER,
    FloodWatch,
    SilenceWatch,
    Topics,
    strangers_problem,
)

STATUS = "Min distance: 1.946 m, angle: -0.009 rad"
TOPICS = Topics("python3 lidar_node.py", "/scan", "/lidar_status", "/fossbot2/obstacle_warning")


def missed(tick: int, late_after: float | None, *, bool_too: bool = False) -> Answers:
    """A scan's answers that missed the deadline; its own status came `late_after` s on."""
    late = [] if late_after is None else [Received(STATUS, late_after, tick=tick)]
    if bool_too:
        late.append(Received(True, 0.1, tick=tick))
    return Answers(timed_out=True, late=late)


def ending(late_afters: list[float | None], **kwargs) -> Answers:
    watch = SilenceWatch(TOPICS, scan_timeout=0.5)
    answers = Answers()
    for tick, after in enumerate(late_afters, start=1):
        answers = missed(tick, after, bool_too=kwargs.get("bool_too", False))
        watch.see(answers, tick, empty=kwargs.get("empty", False))
    return answers


def test_three_late_answers_are_too_late() -> None:
    answers = ending([1.5, 1.5, 1.5])
    assert answers.problem == (
        "node answers too late: 3 scans in a row missed the 0.5 s deadline "
        "(the last answer came after 1.50 s)"
    )
    assert answers.silent  # the node runs: its slowness is its verdict


def test_late_answers_then_one_not_yet_come_are_too_late_not_stopped() -> None:
    assert ending([1.5, 1.6, None]).problem == (
        "node answers too late: 3 scans in a row missed the 0.5 s deadline "
        "(tick 2's answer came after 1.60 s; the last scan's had not come when the harness "
        "stopped waiting)"
    )


def test_no_answer_at_all_is_stopped() -> None:
    problem = ending([None, None, None]).problem
    assert problem is not None
    assert problem.startswith("node stopped answering: no status on /lidar_status for 3 scans")
    assert problem.endswith("(the node is still running: stuck in a callback, or not publishing)")


def test_bools_without_statuses_say_the_node_is_not_stuck() -> None:
    problem = ending([None] * STOPPED_AFTER, bool_too=True).problem
    assert problem is not None
    assert "though it published /fossbot2/obstacle_warning for them" in problem


def test_silent_only_when_nothing_is_in_range_says_so() -> None:
    problem = ending([None] * STOPPED_AFTER, empty=True).problem
    assert problem == (
        "node python3 lidar_node.py is running and subscribed to /scan but published nothing "
        "on /lidar_status for 3 scans in a row, none of which had a valid return: a status is "
        'expected when nothing is in range too (e.g. "no obstacle")'
    )


def test_fewer_than_the_limit_say_nothing() -> None:
    answers = ending([None] * (STOPPED_AFTER - 1))
    assert answers.problem is None and not answers.silent


def test_an_earlier_problem_is_kept() -> None:
    watch = SilenceWatch(TOPICS, scan_timeout=0.5)
    for tick in (1, 2):
        watch.see(missed(tick, None), tick)
    answers = missed(3, None)
    answers.problem = "node crashed"
    watch.see(answers, 3)
    assert answers.problem == "node crashed" and not answers.silent


def test_an_answer_in_time_starts_the_count_again() -> None:
    watch = SilenceWatch(TOPICS, scan_timeout=0.5)
    watch.see(missed(1, 1.5), 1)
    watch.see(Answers(statuses=[Received(STATUS, 0.1)]), 2)
    answers = Answers()
    for tick in (3, 4, 5):
        answers = missed(tick, None)
        watch.see(answers, tick)
    assert answers.problem is not None and answers.problem.startswith("node stopped answering")


def flood(per_scan: int, seconds_per_scan: float, scans: int = FLOOD_SCANS) -> Answers:
    watch = FloodWatch("/lidar_status", "/fossbot2/obstacle_warning")
    watch.restart(7, 7)  # what warm-up heard is not counted
    statuses = 7
    answers = Answers()
    for _ in range(scans):
        statuses += per_scan
        answers = Answers()
        watch.see(answers, statuses, 7 + scans, seconds_per_scan)
    return answers


def test_many_messages_a_scan_fast_are_a_flood() -> None:
    problem = flood(per_scan=20, seconds_per_scan=0.05).problem
    assert problem == (
        "node floods /lidar_status: 100 messages in 0.25 s over the last 5 scans "
        "(one per scan expected)"
    )


def test_a_timer_during_long_waits_is_no_flood() -> None:
    # 10 a scan, but each scan took 1 s (a 10 Hz timer): far below FLOOD_RATE_HZ.
    assert flood(per_scan=10, seconds_per_scan=1.0).problem is None


def test_a_few_messages_are_no_flood_however_fast() -> None:
    assert flood(per_scan=(FLOOD_MIN - 1) // FLOOD_SCANS, seconds_per_scan=0.001).problem is None


def test_strangers_are_named_with_the_domain() -> None:
    problem = strangers_problem("/other_node", 17)
    assert problem is not None
    assert problem.startswith("another ROS node shares this run's domain (17): /other_node;")
    assert strangers_problem("", 17) is None
