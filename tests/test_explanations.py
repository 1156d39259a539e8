"""Explanations name the real cause (issue 27): per-tick hints, run-level hints, the crash
text and the run's notes, built by hand (pure), then through the inprocess link."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from gazebo_scans import INC, make_scan
from rich.console import Console

from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.judge.run_hints import run_hint
from harness.lidar.scan import Scan
from harness.links import LinkOptions
from harness.nodes.process import last_error
from harness.report.terminal import print_results
from harness.runner import scenario_run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario

THRESHOLD = 0.5
FUNCTIONS = Path(__file__).parent / "explained_functions.py"


def status_for(scan: Scan) -> tuple[str, bool]:
    """What a correct node says."""
    valid = scan.valid_mask()
    if not valid.any():
        return "No obstacle", False
    i = int(np.flatnonzero(valid & (scan.ranges == scan.ranges[valid].min()))[0])
    d = float(scan.ranges[i])
    return f"Min distance: {d:.3f} m, angle: {scan.angle_min + i * INC:.3f} rad", d < THRESHOLD


def answers(status: str | None, warning: bool | None = None, **kw) -> Answers:
    if status is None:
        return Answers(waited=1.0, timed_out=True, **kw)
    return Answers(
        statuses=[Received(status, 0.01)],
        warnings=[] if warning is None else [Received(warning, 0.01)],
        waited=0.01,
        **kw,
    )


def result_of(scans: list[Scan], replies: list[Answers]) -> RunResult:
    """A run judged tick by tick, as the runner records it."""
    oracle = Oracle(THRESHOLD)
    result = RunResult("hand_made", "ros2", 0, THRESHOLD, "clean")
    for tick, (scan, reply) in enumerate(zip(scans, replies, strict=True)):
        verdict = oracle.judge(tick, tick / 10, scan, reply)
        result.records.append(TickRecord(tick, tick / 10, 0.0, 0.0, 0.0, scan, reply, verdict))
    return result


def approach(distances: list[float], beam: int = 179) -> list[Scan]:
    return [make_scan({beam: d}) for d in distances]


def hint_of(result: RunResult) -> str:
    return (
        run_hint(
            [r.verdict for r in result.records],
            result.threshold,
            scans=[r.scan for r in result.records],
        )
        or ""
    )


# -- 1. one scan late ---------------------------------------------------------------


def test_a_node_one_scan_late_is_named_and_gets_no_threshold_hint() -> None:
    """Each answer is the scan before's: 'the answers match the previous scan's'."""
    scans = approach([1.0 - 0.04 * k for k in range(20)])  # 1.00 m to 0.24 m
    replies = [answers("No obstacle", False)]
    replies += [answers(*status_for(before)) for before in scans[:-1]]
    result = result_of(scans, replies)
    first = result.first_failure or ""
    assert first.startswith("hand_made: t=0.00 s tick 0: ")
    assert (
        "hint: the answers match the previous scan's (19 of the 19 failed ticks with a status, "
        "from tick 1): is the node answering one scan late (e.g. publishing a stored result "
        "before computing the new one)?" in first
    )
    assert "hard-coded" not in first and "rounded" not in first


def test_wrong_answers_that_do_not_fit_the_scan_before_are_not_called_late() -> None:
    """A constant wrong angle is not lateness, even where the distance is the same."""
    scans = [make_scan({100 + k: 0.8}) for k in range(10)]  # turning beside a wall
    replies = [answers("Min distance: 0.800 m, angle: 0.500 rad", False) for _ in scans]
    assert "previous scan" not in hint_of(result_of(scans, replies))


# -- 2. rounded before the comparison --------------------------------------------------


def test_rounding_before_the_comparison_is_told_apart_from_a_hard_coded_threshold() -> None:
    """round(d, 1) < 0.5 warns below 0.45 m: rounding, not another threshold."""
    scans = approach([0.60 - 0.01 * k for k in range(30)])  # 0.60 m to 0.31 m
    replies = []
    for scan in scans:
        status, _ = status_for(scan)
        d = float(scan.ranges[179])
        replies.append(answers(status, round(d, 1) < THRESHOLD))
    first = result_of(scans, replies).first_failure or ""
    assert "it looks like the distance is rounded before it is compared with the threshold" in first
    assert "a distance rounded to 1 decimal crosses 0.5 m at 0.45 m" in first
    assert "its own status said" in first  # 0.47 m < 0.5 m, yet no warning
    assert "hard-coded" not in first


def test_a_hard_coded_threshold_still_gets_its_hint() -> None:
    """The harness passes 0.5 m; the node warns below 0.3 m: no rounding fits that."""
    scans = approach([0.60 - 0.01 * k for k in range(40)])  # 0.60 m to 0.21 m
    replies = [answers(status_for(s)[0], float(s.ranges[179]) < 0.3) for s in scans]
    first = result_of(scans, replies).first_failure or ""
    assert "the node warns as if its threshold were between 0.29 and 0.30 m" in first
    assert "is the threshold hard-coded?" in first and "rounded" not in first


# -- 3. angle_min forgotten ----------------------------------------------------------


@pytest.mark.parametrize("beam", [0, 179])
def test_an_angle_without_angle_min_is_named(beam: int) -> None:
    """index * increment, even at beam 0 (where it also equals the index)."""
    scan = make_scan({beam: 1.0})
    v = Oracle(THRESHOLD).judge(0, 0.0, scan, answers(f"Obstacle at 1.0 m, {beam * INC:.3f} rad"))
    assert "the angle looks measured from beam 0, without angle_min (-3.142 rad here)" in (
        v.explanation
    )
    assert "beam index" not in v.explanation


def test_the_beam_index_hint_stays_for_an_index() -> None:
    scan = make_scan({100: 1.0})
    v = Oracle(THRESHOLD).judge(0, 0.0, scan, answers("Obstacle at 1.0 m, angle 100"))
    assert "looks like the beam index, not its angle" in v.explanation
    assert "angle_min" not in v.explanation


# -- 4. silent when nothing is in range -----------------------------------------------


def test_silence_on_every_empty_scan_is_named() -> None:
    scans = approach([0.8, 0.9, 1.0]) + [make_scan() for _ in range(3)]
    replies = [answers(*status_for(s)) for s in scans[:3]] + [answers(None)] * 3
    first = result_of(scans, replies).first_failure or ""
    assert "tick 3: expected no obstacle" in first
    assert (
        "hint: the node published no status for the scans with no valid return (ticks 3-5) and "
        'answered the others: a status is expected when nothing is in range too (e.g. "no '
        'obstacle")' in first
    )
    assert "only when it changes" not in first


# -- 5. a latched warning ---------------------------------------------------------------


def test_a_warning_that_never_clears_is_named_with_its_ticks() -> None:
    scans = approach([0.3, 0.4, 0.6, 0.8, 1.0, 1.2])
    replies = [answers(status_for(s)[0], True) for s in scans]
    first = result_of(scans, replies).first_failure or ""
    assert first.startswith("hand_made: t=0.20 s tick 2: ")
    assert (
        "hint: warning True since tick 0 and never cleared (the scans from tick 2 on had "
        "nothing within the threshold)" in first
    )


def test_a_warning_rightly_true_to_the_end_is_not_latched() -> None:
    """Warning early (a larger threshold) while closing in: not 'never cleared'."""
    scans = approach([0.7, 0.6, 0.55, 0.45, 0.4, 0.3])
    replies = [answers(status_for(s)[0], float(s.ranges[179]) < 0.65) for s in scans]
    assert "never cleared" not in (result_of(scans, replies).first_failure or "")


# -- 6. a crash ----------------------------------------------------------------------------

TRACEBACK = """\
Traceback (most recent call last):
  File "/opt/ros/lib/python3.12/site-packages/rclpy/executors.py", line 111, in await_or_execute
    return callback(*args)
           ^^^^^^^^^^^^^^^
  File "/home/student/ws/src/lab07/lab07/lidar_node.py", line 85, in on_scan
    best = min(valid)
           ^^^^^^^^^^
ValueError: min() arg is an empty sequence
[ros2run]: Process exited with failure 1
"""


def test_the_last_error_of_a_traceback_is_its_exception_and_where() -> None:
    assert last_error(TRACEBACK) == (
        "ValueError: min() arg is an empty sequence (lidar_node.py line 85, in on_scan: "
        "best = min(valid))"
    )
    assert last_error("a\nb\n\nterminate called\n  what():  boom\n") == (
        "b | terminate called |   what():  boom"
    )
    assert last_error("") == ""


def test_a_crash_is_the_tick_failure_not_a_link_problem() -> None:
    crash = (
        "node python3 lidar_node.py crashed on this scan: it exited with code 1; last stderr: "
        "ValueError: min() arg is an empty sequence (lidar_node.py line 85, in on_scan: ...)"
    )
    v = Oracle(THRESHOLD).judge(7, 0.7, make_scan(), Answers(problem=crash, crashed=True))
    assert v.failures == (crash,)
    assert "link problem" not in v.explanation and "no status arrived" not in v.explanation


def test_a_run_ended_by_a_crash_says_it_once() -> None:
    """The terminal's 'run ended' line would repeat the crash: left out."""
    crash = "node N crashed on this scan: it exited with code 1; last stderr: ValueError: x"
    scans = approach([0.8])
    result = result_of(scans, [answers(None, problem=crash, crashed=True)])
    result.error = f"t=0.00 s tick 0: {crash}"
    out = printed([result])
    assert out.count("crashed on this scan") == 1 and "run ended" not in out


# -- 7. a warning on another topic ---------------------------------------------------------

NOTE = (
    "the node publishes a Bool on /warning, not /obstacle_warning: pass --warning-topic /warning "
    "if that is the lab's name"
)


def printed(results: list[RunResult]) -> str:
    out = io.StringIO()
    print_results(Console(file=out, width=1000, color_system=None), results)
    return out.getvalue()


def test_a_note_is_printed_once_for_the_run_outside_the_node_output() -> None:
    failed = []
    for name in ("approach_wall", "drive_past_10m"):
        scans = approach([0.3])
        result = result_of(scans, [answers(status_for(scans[0])[0], None)])
        result.scenario = name
        result.notes = [NOTE]
        result.diagnostics = f"node stderr (last lines):\n[INFO] {name} up\n{NOTE}"
        failed.append(result)
    out = printed(failed)
    assert out.count(NOTE) == 1
    assert out.index(f"note: {NOTE}") > out.index("[INFO] drive_past_10m up")


# -- status only on change; only the first answer wrong -------------------------------------


def test_a_status_published_only_on_change_is_named() -> None:
    scans = approach([1.0, 0.9, 0.9, 0.9, 0.8])
    replies = [answers(*status_for(scans[0])), answers(*status_for(scans[1]))]
    replies += [answers(None), answers(None), answers(*status_for(scans[4]))]
    first = result_of(scans, replies).first_failure or ""
    assert first.startswith("hand_made: t=0.20 s tick 2: ")
    assert (
        "hint: the node published no status at ticks 2-3, where its last status ('Min distance: "
        "0.900 m, angle: -0.009 rad', tick 1) still held: it looks like it publishes its status "
        "only when it changes, but a status is expected for every scan" in first
    )


def test_answers_that_came_late_are_not_called_a_status_only_on_change() -> None:
    """A node slower than the deadline answers every scan, late: its answers came, so no
    hint about silence (only when it changes, nothing when clear) fits it."""
    scans = approach([1.0, 1.0, 1.0, 1.0])  # the first status still holds for the others
    replies = [answers(*status_for(scans[0]))]
    for tick, scan in enumerate(scans[1:], start=1):
        text, _ = status_for(scan)
        replies.append(answers(None, late=[Received(text, 2.0, tick)]))
    first = result_of(scans, replies).first_failure or ""
    assert "it came after 2.00 s" in first
    assert "hint" not in first, first


def test_only_the_first_answer_wrong_is_named() -> None:
    scans = approach([1.0, 0.9, 0.8, 0.7])
    replies = [answers("Min distance: 0.000 m, angle: 0.000 rad", False)]
    replies += [answers(*status_for(s)) for s in scans[1:]]
    first = result_of(scans, replies).first_failure or ""
    assert first.startswith("hand_made: t=0.00 s tick 0: ")
    assert "hint: only the node's first answer (tick 0) was wrong, every later one was right" in (
        first
    )


def test_a_passing_run_has_no_hint() -> None:
    scans = approach([1.0, 0.4])
    result = result_of(scans, [answers(*status_for(s)) for s in scans])
    assert result.ok and result.first_failure is None and hint_of(result) == ""


# -- the same, through a real link (inprocess: a child process per scenario) ----------------


def run_function(scenario_name: str, fn: str) -> RunResult:
    scenario = resolve_scenario(scenario_name)
    options = LinkOptions(processor=f"{FUNCTIONS}:{fn}")
    return scenario_run.run(scenario, "inprocess", options, RunSettings())


@pytest.mark.parametrize(
    ("fn", "scenario", "phrase"),
    [
        ("one_scan_late", "approach_wall", "the answers match the previous scan's"),
        (
            "rounds_before_compare",
            "approach_wall",
            "it looks like the distance is rounded before it is compared with the threshold",
        ),
        ("latched_warning", "drive_past_10m", "warning True since tick 0 and never cleared"),
    ],
)
def test_run_hints_through_the_inprocess_link(fn: str, scenario: str, phrase: str) -> None:
    first = run_function(scenario, fn).first_failure or ""
    assert phrase in first, first
    assert "hard-coded" not in first, first
