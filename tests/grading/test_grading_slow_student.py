"""A slow but correct student is graded PASS: speed decides only a node's own verdict, and
0.3 s a scan is within the 1 s deadline. One single-file student (the test suite's student
node, correct, its callback taking 0.3 s a scan as a student's that logs and plots would)
graded for real over ROS 2, in its sandbox, on three short scenarios shaped like the lab's."""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import pytest
from command_line import COMMAND
from grading_class import STUDENT_NODE, patch
from short_scenarios import DRIVE_AWAY, NEAR_WALL, nothing_in_range

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]

DELAY_S = 0.3  # a scan's callback, before it answers
SCENARIOS = {"wall_ahead": NEAR_WALL, "drive_away": DRIVE_AWAY, "clear": nothing_in_range()}


def slow_student(folder: Path) -> Path:
    """One .py file: the correct variant, every scan's callback taking DELAY_S."""
    folder.mkdir(parents=True)
    node = folder / "lidar_node.py"
    node.write_text('import sys\n\nsys.argv[1:1] = ["correct"]\n' + STUDENT_NODE.read_text())
    patch(node, 'declare_parameter("delay_s", 0.0)', f'declare_parameter("delay_s", {DELAY_S})')
    return folder


def test_a_correct_student_at_a_third_of_a_second_a_scan_passes_every_scenario(
    tmp_path: Path,
) -> None:
    slow_student(tmp_path / "class" / "erin")
    files = []
    for name, text in SCENARIOS.items():
        files.append(tmp_path / f"{name}.yaml")
        files[-1].write_text(text)
    done = subprocess.run(
        [*COMMAND, "grade", str(tmp_path / "class"), "--out", str(tmp_path / "grades")]
        + ["--scenario", ",".join(map(str, files)), "--workers", "1", "--no-audit"],
        capture_output=True,
        text=True,
        timeout=280,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp_path / "grades" / "grades.csv", newline="", encoding="utf-8") as handle:
        erin = next(csv.DictReader(handle))
    assert [erin[name] for name in SCENARIOS] == ["PASS"] * len(SCENARIOS), erin
    assert erin["passed"] == f"{len(SCENARIOS)}/{len(SCENARIOS)}" and not erin["first_failure"]
