"""Which folders are students, and what each handed in (files only, milliseconds)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.grading.discover import GRADES_MARKER, discover, student_in

NODE = "import rclpy\n"


def touch(path: Path, text: str = "") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_each_layout_is_recognised(tmp_path: Path) -> None:
    """Workspace (src/), package, nested package, script; junk is a student with a reason."""
    touch(tmp_path / "ws" / "src" / "repo" / "pkg" / "package.xml")
    touch(tmp_path / "pkg" / "package.xml")
    touch(tmp_path / "nested" / "fossbot_lidar_processing" / "package.xml")
    touch(tmp_path / "script" / "my_node.py", NODE)
    touch(tmp_path / "notes" / "readme.txt")
    found = {s.name: s for s in discover([tmp_path]).students}
    assert {name: s.kind for name, s in found.items()} == {
        "ws": "workspace",
        "pkg": "package",
        "nested": "workspace",
        "script": "script",
        "notes": "none",
    }
    assert found["ws"].base_paths == (tmp_path / "ws" / "src" / "repo" / "pkg",)
    assert found["pkg"].base_paths == (tmp_path / "pkg",)
    assert found["script"].script == tmp_path / "script" / "my_node.py"
    assert found["notes"].problem == "no node found: no package.xml and no .py file"


def test_build_output_and_ignored_folders_are_not_searched(tmp_path: Path) -> None:
    """A student's own build/install/log and COLCON_IGNOREd folders hold no packages."""
    ws = tmp_path / "ws"
    touch(ws / "src" / "pkg" / "package.xml")
    touch(ws / "src" / "old" / "COLCON_IGNORE")
    touch(ws / "src" / "old" / "package.xml")
    touch(ws / "install" / "pkg" / "share" / "pkg" / "package.xml")
    assert student_in(ws).base_paths == (ws / "src" / "pkg",)


def test_the_node_script_is_the_one_importing_rclpy(tmp_path: Path) -> None:
    """Helpers beside the node are fine; two candidate nodes are ambiguous."""
    touch(tmp_path / "a" / "helpers.py", "import math\n")
    touch(tmp_path / "a" / "node.py", "from rclpy.node import Node\n")
    touch(tmp_path / "a" / "setup.py", NODE)
    assert student_in(tmp_path / "a").script == tmp_path / "a" / "node.py"
    touch(tmp_path / "b" / "one.py", NODE)
    touch(tmp_path / "b" / "two.py", NODE)
    ambiguous = student_in(tmp_path / "b")
    assert ambiguous.kind == "none"
    assert ambiguous.problem is not None and "one.py, two.py" in ambiguous.problem


def test_a_workspace_given_directly_is_one_student(tmp_path: Path) -> None:
    """DIR with src/ (or a package.xml) is one hand-in, named after the folder."""
    ws = tmp_path / "maria_ws"
    touch(ws / "src" / "pkg" / "package.xml")
    touch(ws / "src" / "pkg" / "pkg" / "node.py", NODE)
    [student] = discover([ws]).students
    assert (student.name, student.kind) == ("maria_ws", "workspace")


def test_same_name_in_two_folders_is_told_apart(tmp_path: Path) -> None:
    """Two sections each with an 'alex': names get the section, slugs stay file-safe."""
    for section in ("mon", "tue"):
        touch(tmp_path / section / "alex" / "package.xml")
    students = discover([tmp_path / "mon", tmp_path / "tue"]).students
    assert [(s.name, s.slug) for s in students] == [
        ("mon/alex", "mon_alex"),
        ("tue/alex", "tue_alex"),
    ]


def test_output_folder_hidden_folders_and_files_are_skipped(tmp_path: Path) -> None:
    """--out inside the class folder, a .git folder and OS litter are never students; a
    zip is noted to unpack, a loose file is a row saying why it is not graded."""
    touch(tmp_path / "ana" / "package.xml")
    touch(tmp_path / "grades" / GRADES_MARKER)
    touch(tmp_path / "old_grades" / GRADES_MARKER)
    touch(tmp_path / ".git" / "config")
    touch(tmp_path / ".DS_Store")
    touch(tmp_path / "Thumbs.db")
    touch(tmp_path / "ben.zip")
    touch(tmp_path / "cleo.pdf")
    found = discover([tmp_path], exclude=tmp_path / "grades")
    assert [(s.name, s.kind, s.problem) for s in found.students] == [
        ("ana", "package", None),
        ("cleo.pdf", "none", "not a submission: a file, not a folder or archive"),
    ]
    assert [(a.name, a.path) for a in found.archives] == [("ben", tmp_path / "ben.zip")]
    assert [note.split(":")[1] for note in found.skipped] == [
        " an output folder of `fossbot-hil grade`",
    ]


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda root: root / "missing", "no such folder"),
        (lambda root: touch(root / "file.txt"), "not a folder"),
        (lambda root: root, "no students found"),
        (lambda root: touch(root / "notes.txt").parent, "no students found"),
    ],
)
def test_nothing_to_grade_is_a_usage_error(tmp_path: Path, make, match: str) -> None:
    """Missing folder, a file, an empty folder, a folder of loose files: ConfigError."""
    with pytest.raises(ConfigError, match=match):
        discover([make(tmp_path)])


def test_hand_ins_that_cannot_run_are_students_with_reasons(tmp_path: Path) -> None:
    """Folders with nothing to run are a class all the same: each a row saying why."""
    touch(tmp_path / "ana" / "notes.txt")
    touch(tmp_path / "ben" / "one.py", NODE)
    touch(tmp_path / "ben" / "two.py", NODE)
    (tmp_path / "cleo").mkdir()
    found = discover([tmp_path]).students
    assert [(s.name, s.kind) for s in found] == [("ana", "none"), ("ben", "none"), ("cleo", "none")]
    assert [s.problem.split(":")[0] for s in found if s.problem] == [
        "no node found",
        "cannot tell which .py file is the node (one.py, two.py)",
        "no node found",
    ]


HELPER = (
    "import rclpy\nfrom rclpy.node import Node\n\n\ndef nearest(ranges):\n    return min(ranges)\n"
)
GUARDED = (
    "import rclpy\nfrom rclpy.node import Node\n\n\nclass Lidar(Node):\n    pass\n\n\n"
    "def main():\n    rclpy.init()\n    rclpy.spin(Lidar())\n\n\n"
    'if __name__ == "__main__":\n    main()\n'
)


def test_the_labs_node_name_wins_over_a_helper_importing_rclpy(tmp_path: Path) -> None:
    """fossbot_lidar_node.py beside a helper module that imports rclpy too: the node."""
    touch(tmp_path / "a" / "fossbot_lidar_node.py", NODE)
    touch(tmp_path / "a" / "lidar_helpers.py", GUARDED)  # even one that could run alone
    assert student_in(tmp_path / "a").script == tmp_path / "a" / "fossbot_lidar_node.py"


@pytest.mark.parametrize(
    "guard",
    [
        GUARDED,
        # rclpy's names imported, the node made and spun in the guard itself
        "from rclpy import init as start, spin\nfrom rclpy.node import Node\n"
        'if "__main__" == __name__:\n    start()\n    spin(Node("n"))\n',
        # an executor's spin, through two of the script's own functions
        "import rclpy\nfrom rclpy.executors import SingleThreadedExecutor\n\n\n"
        "def run(e):\n    e.spin()\n\n\ndef main():\n    run(SingleThreadedExecutor())\n\n\n"
        'if __name__ == "__main__":\n    main()\n',
    ],
)
def test_otherwise_the_node_is_the_one_whose_main_guard_starts_a_node(
    tmp_path: Path, guard: str
) -> None:
    """No file of the lab's name: the script whose __main__ guard starts a node is it; a
    helper's guard that only tries out its functions does not count."""
    touch(tmp_path / "my_node.py", guard)
    touch(tmp_path / "helpers.py", HELPER + 'if __name__ == "__main__":\n    print(nearest([1]))\n')
    assert student_in(tmp_path).script == tmp_path / "my_node.py"


def test_two_nodes_that_could_each_run_are_ambiguous(tmp_path: Path) -> None:
    """Two guarded nodes and no file of the lab's name: the reason names the fix."""
    touch(tmp_path / "old_node.py", GUARDED)
    touch(tmp_path / "new_node.py", GUARDED)
    touch(tmp_path / "broken.py", "import rclpy\nif __name__ == '__main__':\n    def (:\n")
    student = student_in(tmp_path)
    assert student.kind == "none"
    assert student.problem == (
        "cannot tell which .py file is the node (new_node.py, old_node.py): name the node "
        "fossbot_lidar_node.py, or hand in a package"
    )
