"""A node that cannot start because of how it was set up: one line, exit 2, and the fix.

Real interpreters: a fresh virtual environment without the harness (so without
rclpy) stands for a student's `python3` outside the harness's venv.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil

from harness.errors import ConfigError
from harness.nodes.command import shell_node
from harness.nodes.setup_problems import setup_problem

STUDENT = Path(__file__).parent / "ros" / "student_node.py"


@pytest.mark.parametrize(
    ("output", "argv", "expected"),
    [
        ("ModuleNotFoundError: No module named 'rclpy'", ["/usr/bin/python3", "n.py"], "rclpy"),
        ("ModuleNotFoundError: No module named 'std_msgs.msg'", ["python3"], "std_msgs"),
        ("ModuleNotFoundError: No module named 'rcl_interfaces'", ["python3"], "rcl_interfaces"),
        ("ModuleNotFoundError: No module named 'geometry_msgs.msg'", ["python3"], "geometry_msgs"),
        ("ModuleNotFoundError: No module named 'std_srvs'", ["python3"], "std_srvs"),
        ("ModuleNotFoundError: No module named 'numpy'", ["python3", "n.py"], None),
        ("ModuleNotFoundError: No module named 'my_msgs_helper'", ["python3", "n.py"], None),
        ("ZeroDivisionError: division by zero", ["python3", "n.py"], None),
    ],
)
def test_only_a_missing_ros_module_is_a_setup_problem(
    output: str, argv: list[str], expected: str | None
) -> None:
    problem = setup_problem(output, argv)
    if expected is None:
        assert problem is None
    else:
        assert problem is not None and f"cannot import {expected}" in problem
        assert sys.executable in problem


def test_a_script_is_run_with_the_harness_python_and_a_missing_one_is_refused(
    tmp_path: Path,
) -> None:
    script = tmp_path / "node.py"
    script.write_text("")  # not executable: run with this interpreter, as grade does
    assert shell_node(f"{script} --flag").argv == (sys.executable, str(script), "--flag")
    for command in (f"python3 {tmp_path}/gone.py", f"python3 -u -W ignore {tmp_path}/gone.py"):
        with pytest.raises(ConfigError, match=f"no such script {tmp_path}/gone.py"):
            shell_node(command)
    assert shell_node("python3 -m some.module").argv[1:] == ("-m", "some.module")


@pytest.fixture(scope="module")
def bare_python(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The Python of a fresh venv: no rclpy, like a student's python3 outside the harness's."""
    folder = tmp_path_factory.mktemp("bare") / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder)], check=True)
    return folder / "bin" / "python"


@pytest.mark.ros
def test_a_python_without_rclpy_exits_2_naming_the_fix(bare_python: Path) -> None:
    done = fossbot_hil("run", "approach_wall", "--node", f"{bare_python} {STUDENT} correct")
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert f"the node's Python ({bare_python}) cannot import rclpy" in lines[0]
    assert f"this harness's Python ({sys.executable})" in lines[0]


@pytest.mark.ros
def test_a_bare_script_path_runs_like_grade_runs_it() -> None:
    done = fossbot_hil("run", "approach_wall", "--node", f"{STUDENT} correct")
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_missing_script_exits_2_before_anything_runs(tmp_path: Path) -> None:
    script = tmp_path / "nope.py"
    done = fossbot_hil("run", "approach_wall", "--node", f"python3 {script}")
    assert done.returncode == 2
    expected = f"fossbot-hil: error: --node 'python3 {script}': no such script {script}"
    assert done.stderr.strip() == expected
