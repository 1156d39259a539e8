"""harness.grading.autograder's steps without ROS: what a submission holds, and the
results.json of one that cannot be run (examples/gradescope/run_autograder calls them)."""

from __future__ import annotations

import shlex
import sys
import zipfile
from pathlib import Path

import pytest
from gradescope_schema import read_results

from harness.grading.autograder import main, node_options


def test_a_lone_zip_is_unpacked_and_wrapper_folders_looked_through(tmp_path: Path) -> None:
    submission = tmp_path / "submission"
    submission.mkdir()
    with zipfile.ZipFile(submission / "lab07.zip", "w") as archive:
        archive.writestr("__MACOSX/lab07/._lidar_node.py", "")  # a file manager's litter
        archive.writestr("lab07/node/lidar_node.py", "import rclpy\n")
        archive.writestr("lab07/node/.hidden.py", "")
    options = node_options(submission, tmp_path / "work")
    node = tmp_path / "work" / "unpacked" / "lab07" / "node" / "lidar_node.py"
    assert options == ["--node", f"{shlex.quote(sys.executable)} {shlex.quote(str(node))}"]


def test_prepare_prints_the_node_options_one_per_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "my node.py").write_text("import rclpy\n")
    assert main(["prepare", str(tmp_path / "sub"), str(tmp_path / "work")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "--node" and shlex.split(lines[1])[-1] == str(
        tmp_path / "sub" / "my node.py"
    )


@pytest.mark.parametrize(
    ("files", "why"),
    [
        ({}, "no node found: no package.xml and no .py file"),
        (
            {"a.py": "x = 1\n", "b.py": "y = 2\n"},
            "cannot tell which .py file is the node (a.py, b.py)",
        ),
        ({"hand-in.zip": "not a zip"}, "hand-in.zip: archive could not be unpacked"),
    ],
)
def test_prepare_says_why_there_is_nothing_to_run(
    files: dict[str, str], why: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    submission = tmp_path / "submission"
    submission.mkdir()
    for name, text in files.items():
        (submission / name).write_text(text)
    assert main(["prepare", str(submission), str(tmp_path / "work")]) == 1
    said = capsys.readouterr().out
    assert said.startswith(why) and str(tmp_path) not in said


def test_not_graded_writes_the_grading_files_tests_at_0(tmp_path: Path) -> None:
    (tmp_path / "hidden").mkdir()
    (tmp_path / "hidden" / "maze.yaml").write_text("broken: [")  # unreadable: named by file
    grading = tmp_path / "grading.yaml"
    grading.write_text(
        "scenarios:\n  - approach_wall\n  - scenario: hidden/maze.yaml\n    hidden: true\n"
        "points: 4\n"
    )
    out = tmp_path / "results" / "results.json"
    reason = f"did not build: {tmp_path}/submission/setup.py line 3: SyntaxError"
    assert (
        main(["not-graded", "--grading", str(grading), "--reason", reason, "--out", str(out)]) == 0
    )
    data = read_results(out)
    assert data["score"] == 0.0
    assert data["output"] == "not graded: did not build: setup.py line 3: SyntaxError"
    assert [(t["name"], t["max_score"], t["score"]) for t in data["tests"]] == [
        ("approach_wall", 2.0, 0.0),
        ("hidden 1", 2.0, 0.0),
    ]
    assert "maze" not in out.read_text()


def test_not_graded_without_a_grading_file_lists_the_shipped_scenarios(tmp_path: Path) -> None:
    out = tmp_path / "results.json"
    assert main(["not-graded", "--reason", "nothing handed in", "--out", str(out)]) == 0
    data = read_results(out)
    assert len(data["tests"]) == 7 and all(t["max_score"] == 1.0 for t in data["tests"])
