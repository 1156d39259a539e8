"""`fossbot-hil grade` on script hand-ins split in two: the node and a helper module.

Students split the node: the node file and a module of their own that
imports rclpy too. A real grading (bubblewrap sandbox, nodes over DDS, two
short scenarios) must run each student's node, not stop at "cannot tell which
.py file is the node"; a class where no hand-in can run is still a table.
"""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import pytest
from command_line import COMMAND
from grading_class import STUDENT_NODE
from short_scenarios import NEAR_WALL, nothing_in_range

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(180)]

SCENARIOS = ("wall_ahead", "nothing_in_range")


def _variant(name: str) -> str:
    """The test suite's student node as a module, made to run `name` (one of its variants)."""
    return f"import sys\n\nsys.argv[1:1] = [{name!r}]\n" + STUDENT_NODE.read_text()


def lab_named_node(folder: Path, variant: str) -> Path:
    """fossbot_lidar_node.py starts the node that lidar_logic.py (importing rclpy) holds."""
    folder.mkdir(parents=True)
    (folder / "lidar_logic.py").write_text(STUDENT_NODE.read_text())  # has its own guard
    (folder / "fossbot_lidar_node.py").write_text(
        f"import sys\n\nfrom lidar_logic import main\n\nsys.argv[1:1] = [{variant!r}]\n"
        'if __name__ == "__main__":\n    main()\n'
    )
    return folder


def guarded_node(folder: Path) -> Path:
    """my_node.py (its __main__ guard spins the node) and a helper importing rclpy."""
    folder.mkdir(parents=True)
    (folder / "lidar_qos.py").write_text(
        "from rclpy.qos import qos_profile_sensor_data\n\nQOS = qos_profile_sensor_data\n"
    )
    (folder / "my_node.py").write_text("import lidar_qos  # noqa: F401\n" + _variant("correct"))
    return folder


def grade(classroom: Path, here: Path) -> tuple[subprocess.CompletedProcess[str], dict]:
    """Grade `classroom` over the short scenarios into here/grades; the CSV's rows by name."""
    folder = here / "scenarios"
    folder.mkdir()
    for name, text in zip(SCENARIOS, (NEAR_WALL, nothing_in_range()), strict=True):
        (folder / f"{name}.yaml").write_text(text)
    refs = ",".join(str(folder / f"{name}.yaml") for name in SCENARIOS)
    done = subprocess.run(
        [*COMMAND, "grade", str(classroom), "--out", "grades", "--workers", "2"]
        + ["--scenario", refs, "--no-audit"],
        cwd=here,
        capture_output=True,
        text=True,
        timeout=150,
    )
    rows = {}
    if (here / "grades" / "grades.csv").is_file():
        with open(here / "grades" / "grades.csv", newline="", encoding="utf-8") as handle:
            rows = {row["student"]: row for row in csv.DictReader(handle)}
    return done, rows


def test_a_class_of_nodes_with_helper_modules_is_graded(tmp_path: Path) -> None:
    """Each hand-in holds the node and a helper importing rclpy: each node ran, with the
    verdicts its code earns (the one reporting degrees fails the wall, nothing else)."""
    classroom = tmp_path / "class"
    lab_named_node(classroom / "ana", "correct")
    lab_named_node(classroom / "ben", "angle_in_degrees")
    guarded_node(classroom / "cleo")
    (tmp_path / "grader").mkdir()
    done, rows = grade(classroom, tmp_path / "grader")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    verdicts = {name: [row[s] for s in SCENARIOS] for name, row in rows.items()}
    assert verdicts == {
        "ana": ["PASS", "PASS"],
        "ben": ["FAIL", "PASS"],
        "cleo": ["PASS", "PASS"],
    }, rows
    assert "looks like degrees" in rows["ben"]["first_failure"]
    assert [rows[n]["node"] for n in ("ana", "ben", "cleo")] == [
        "fossbot_lidar_node.py (script)",
        "fossbot_lidar_node.py (script)",
        "my_node.py (script)",
    ]


def test_a_class_where_no_hand_in_can_run_is_a_table_of_reasons(tmp_path: Path) -> None:
    """No hand-in to run is no usage error: exit 0, a row each with the reason."""
    classroom = tmp_path / "class"
    (classroom / "ana").mkdir(parents=True)
    (classroom / "ana" / "notes.txt").write_text("I will hand it in next week\n")
    (classroom / "ben").mkdir()
    for name in ("one.py", "two.py"):
        (classroom / "ben" / name).write_text("import rclpy\n")
    (classroom / "cleo.pdf").write_bytes(b"%PDF-1.4\n")
    (tmp_path / "grader").mkdir()
    done, rows = grade(classroom, tmp_path / "grader")
    assert done.returncode == 0, done.stdout + done.stderr
    assert {name: row["first_failure"] for name, row in rows.items()} == {
        "ana": "no node found: no package.xml and no .py file",
        "ben": "cannot tell which .py file is the node (one.py, two.py): name the node "
        "fossbot_lidar_node.py, or hand in a package",
        "cleo.pdf": "not a submission: a file, not a folder or archive",
    }
    assert all(row[s] == "NOT RUN" for row in rows.values() for s in SCENARIOS)
