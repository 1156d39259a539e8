"""Serial HIL end to end: the harness plays the LIDAR, the board's driver and nodes run.

Virtual board: a pty for the USB cable, the bundled board driver and the
node under test each in their own process, watched over real DDS.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

STUDENT = Path(__file__).resolve().parents[1] / "ros" / "student_node.py"


# The whole shipped suite through the virtual board, one device session for the
# run: tests/serial_links/test_whole_run.py.


# Bugs the lab robot's driver lets the node see: a scenario that shows each
# (the whole suite through the board takes ~20 s a node; one scenario ~3 s),
# and the phrase explaining it.
VISIBLE = {
    "angle_in_degrees": ("obstacle_at_side", "looks like degrees"),  # the wall ahead: 0 either way
    "no_bool": ("approach_wall", "got no Bool"),
    "inverted_bool": ("approach_wall", "expected warning"),
    "threshold_hard_coded": ("obstacle_at_side", "expected warning False"),
    "crash_when_nothing_in_range": ("out_of_range", "exited with code 1"),
    "answers_twice": ("approach_wall", "answered twice"),
}


@pytest.mark.parametrize(
    ("variant", "scenario", "phrase"), [(v, *case) for v, case in VISIBLE.items()]
)
def test_student_bugs_caught_through_the_board(variant: str, scenario: str, phrase: str) -> None:
    """The same student nodes, now behind the board's own LIDAR driver."""
    done = fossbot_hil(
        "run", scenario, "--link", "rplidar", "--node", f"{sys.executable} {STUDENT} {variant}"
    )
    assert done.returncode == 1, done.stdout + done.stderr
    assert " tick " in done.stdout or "exited" in done.stdout
    assert phrase in done.stdout


@pytest.mark.parametrize(
    "variant", ["correct", "min_over_raw_ranges", "no_range_min_filter", "angle_without_angle_min"]
)
def test_what_the_lab_driver_hides_is_not_a_failure(variant: str) -> None:
    """Through the lab robot's driver these nodes are right.

    It publishes +inf for every empty bin, drops out-of-limit returns and
    starts at angle 0, so raw min(), a missing range_min filter and a
    missing angle_min give correct answers there (over ROS 2, with other
    driver conventions, the default suite catches them).
    """
    done = fossbot_hil(
        "run",
        "approach_wall",
        "out_of_range",
        "reverse_to_wall",
        "--link",
        "rplidar",
        "--node",
        f"{sys.executable} {STUDENT} {variant}",
    )
    assert done.returncode == 0, done.stdout + done.stderr
