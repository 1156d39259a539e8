"""What a student may read: absolute paths as file names, hidden scenarios as labels (pure)."""

from __future__ import annotations

import pytest

from harness.grading.student_text import for_students, hide_names, shorten_paths


@pytest.mark.parametrize(
    ("text", "shown"),
    [
        ("cannot read /home/ta/course/hidden/corridor.yaml", "cannot read corridor.yaml"),
        ('File "/autograder/submission/node.py", line 3', 'File "node.py", line 3'),
        ("--workspace /autograder/work/colcon: no install", "--workspace colcon: no install"),
        ("raised at (/tmp/pytest-1/student/lidar_node.py:12)", "raised at (lidar_node.py:12)"),
        ("see ~/course/grading.yaml", "see grading.yaml"),
        ("open file:///home/ta/out/index.html", "open index.html"),
        ("'/home/ta/My Course/x.yaml' is missing", "'x.yaml' is missing"),
        ("node /usr/bin/python3 -m x exited", "node python3 -m x exited"),
        ("folder /work/grades/", "folder grades"),
    ],
)
def test_absolute_paths_become_file_names(text: str, shown: str) -> None:
    assert shorten_paths(text) == shown
    assert for_students(text) == shown


@pytest.mark.parametrize(
    "text",
    [
        "status on /lidar_status, warning on /obstacle_warning",  # ROS 2 topics
        "remapped /robot1/scan to /robot1/lidar",  # a namespace is no machine folder
        "drove at 0.3 m/s for 2 s",
        "relative hidden/corridor.yaml and ./node.py and ../x/y.py",
        "a lone /grading.yaml",  # one component: nothing to shorten
        "",
    ],
)
def test_what_is_no_machine_path_stays(text: str) -> None:
    assert for_students(text) == text


def test_hidden_names_become_labels_as_whole_names() -> None:
    hidden = {"narrow_corridor": "hidden 1", "doorway": "hidden 2"}
    text = (
        "narrow_corridor: t=0.50 s tick 5: expected ...; not run: the node did not start in "
        "doorway; narrow_corridor.yaml; narrow_corridor_2 and my_doorway stay"
    )
    assert hide_names(text, hidden) == (
        "hidden 1: t=0.50 s tick 5: expected ...; not run: the node did not start in "
        "hidden 2; hidden 1; narrow_corridor_2 and my_doorway stay"
    )


def test_a_hidden_file_is_hidden_by_its_path_and_by_its_name() -> None:
    path = "/home/ta/course/hidden/secret_maze.yaml"
    hidden = {"maze": "hidden 1", path: "hidden 1", "secret_maze.yaml": "hidden 1"}
    assert for_students(f"cannot load {path}: bad key", hidden_names=hidden) == (
        "cannot load hidden 1: bad key"
    )
    moved = "/srv/copy/hidden/secret_maze.yaml"  # another copy: its name is hidden too
    assert for_students(f"at {moved}", hidden_names=hidden) == "at hidden 1"
    assert "secret" not in for_students(f"'{path}'", hidden_names=hidden)


def test_nothing_but_paths_and_names_changes() -> None:
    """for_students is not an escaper: markup and control characters are the medium's."""
    text = "<b>status</b> \x1b[31m 'quoted' \"too\""
    assert for_students(text, hidden_names={"x": "hidden 1"}) == text
