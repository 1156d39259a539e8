"""Explanations that need a real node over real DDS (issue 27): the first scan judged, a
crash, silence when nothing is in range, a status only on change, a topic elsewhere.

Each runs `fossbot-hil run` on one or two scenarios against a student node variant
(tests/ros/student_node.py); a node that falls silent gets a short deadline, measured
against this machine's load (tests/deadlines.py).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil
from deadlines import GENEROUS_READY_S, short_deadline

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

STUDENT = Path(__file__).parent / "student_node.py"


def student(variant: str) -> str:
    return f"{sys.executable} {STUDENT} {variant}"


def shown(done: subprocess.CompletedProcess[str]) -> str:
    return done.stdout + done.stderr


def first_failure(done: subprocess.CompletedProcess[str], scenario: str) -> str:
    return next(line for line in done.stdout.splitlines() if line.startswith(f"{scenario}: "))


def test_a_wrong_first_answer_is_caught_at_tick_0() -> None:
    """The first scan the node receives is tick 0's, and its answer is judged (it was a
    warm-up exchange, never judged, so this node passed)."""
    done = fossbot_hil("run", "approach_wall", "--node", student("first_answer_wrong"))
    assert done.returncode == 1, shown(done)
    first = first_failure(done, "approach_wall")
    assert first.startswith("approach_wall: t=0.00 s tick 0: "), first
    assert "status 'Min distance: 0.000 m, angle: 0.000 rad' gives 0.00 m" in first
    assert "hint: only the node's first answer (tick 0) was wrong" in first
    assert "(1 more failed tick" not in done.stdout  # tick 0 only


@pytest.mark.parametrize("link", ["ros2", "rplidar"])
def test_a_status_only_on_change_is_judged_from_tick_0_and_named(link: str) -> None:
    """Tick 0 is answered (its status is new) and right; the node fails where its status
    stops changing (the robot stops), and the hint says why.

    The scans before must be answered in time, those after are waited out: a deadline
    short, but measured against this machine's load."""
    deadline = short_deadline()
    done = fossbot_hil(
        "run", "approach_wall", "--link", link, "--timeout", f"{deadline:g}", "--node",
        student("status_on_change"),
    )  # fmt: skip
    assert done.returncode == 1, shown(done)
    assert " tick 0:" not in done.stdout, shown(done)
    first = first_failure(done, "approach_wall")
    assert f"no status within the deadline ({deadline:.2f} s)" in first, first
    assert "it looks like it publishes its status only when it changes" in first, first
    assert "though it published /obstacle_warning for them" in done.stdout, shown(done)
    assert "stuck in a callback, or not publishing" not in done.stdout, shown(done)


def test_a_crash_names_the_exception_not_a_link_problem() -> None:
    done = fossbot_hil("run", "drive_past_10m", "--node", student("crash_when_nothing_in_range"))
    assert done.returncode == 1, shown(done)
    first = first_failure(done, "drive_past_10m")
    assert "expected no obstacle (no valid return: 360 +inf)" in first, first
    assert (
        "crash_when_nothing_in_range crashed on this scan: it exited with code 1; last stderr: "
        "ValueError: min() arg is an empty sequence (student_node.py line " in first
    ), first
    assert "link problem" not in done.stdout and "run ended" not in done.stdout, shown(done)
    assert f'File "{STUDENT}", line ' in done.stdout  # the node's stderr, below


def test_silence_when_nothing_is_in_range_is_not_called_a_start_up_problem() -> None:
    """out_of_range's first scan has no valid return; the node never answers it."""
    done = fossbot_hil(
        "run", "out_of_range", "--ready-timeout", "2", "--node", student("silent_when_clear")
    )
    assert done.returncode == 1, shown(done)
    first = first_failure(done, "out_of_range")
    assert "silent_when_clear is running and subscribed to /scan but published nothing on " in (
        first
    )
    assert (
        "none of which had a valid return (" in first
        and 'a status is expected when nothing is in range too (e.g. "no obstacle")' in first
    ), first
    assert "never answered" not in first


def test_a_warning_on_another_topic_is_noted_once_with_the_option() -> None:
    done = fossbot_hil(
        "run", "approach_wall", "drive_past_10m", "--node", student("correct"),
        "--param", "warning_topic:=/warning",
    )  # fmt: skip
    assert done.returncode == 1, shown(done)
    note = (
        "note: the node publishes a Bool on /warning, not /obstacle_warning: pass "
        "--warning-topic /warning if that is the lab's name"
    )
    assert done.stdout.count(note) == 1, shown(done)
    assert "no Bool came" not in done.stdout
    assert done.stdout.index(note) > done.stdout.index("drive_past_10m: t=")


def test_a_scan_topic_elsewhere_names_the_option() -> None:
    """Told as soon as the graph shows the node reading /scan: the ready timeout is not
    waited out, but the node must come up within it (generous: a loaded machine's start)."""
    done = fossbot_hil(
        "run", "approach_wall", "--node", student("topic_parameter_ignored"),
        "--param", "lidar_topic:=/robot/scan", "--scan-topic", "/robot/scan",
        "--ready-timeout", f"{GENEROUS_READY_S:g}",
    )  # fmt: skip
    assert done.returncode == 1, shown(done)
    assert (
        "it subscribes to a LaserScan on /scan, not /robot/scan: pass --scan-topic /scan if "
        "that is the lab's name" in done.stdout
    ), shown(done)
