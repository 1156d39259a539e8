"""Student builds: the first real error of a colcon log, the installed node, the time limit."""

from __future__ import annotations

from pathlib import Path

import pytest
from grading_class import copy_package, patch

from harness.grading.build import build_error, build_student, check_installed
from harness.grading.discover import student_in

WRAPPED = """\
Starting >>> fossbot_lidar_processing
Traceback (most recent call last):
  File "<string>", line 1, in <module>
  File "/venv/lib/python3.11/site-packages/setuptools/_distutils/core.py", line 267, in run_setup
    exec(code, g)
  File "<string>", line 18
    version='0.1.0'
            ^^^^^^
SyntaxError: invalid syntax. Perhaps you forgot a comma?
Traceback (most recent call last):
  File "/venv/lib/python3.11/subprocess.py", line 571, in run
    raise CalledProcessError(retcode, process.args,
subprocess.CalledProcessError: Command '['python3', '-c', '...']' returned non-zero exit status 1.
Failed   <<< fossbot_lidar_processing [0.23s, exited with code 1]
"""


@pytest.mark.parametrize(
    ("log", "expected"),
    [
        (WRAPPED, "setup.py line 18: SyntaxError: invalid syntax. Perhaps you forgot a comma?"),
        (
            'Traceback (most recent call last):\n  File "/class/ana/pkg/setup.py", line 3, in '
            "<module>\n    import foo\nModuleNotFoundError: No module named 'foo'\n",
            "setup.py line 3: ModuleNotFoundError: No module named 'foo'",
        ),
        (
            "[0.628s] ERROR:colcon:colcon build: Duplicate package names not supported:\n"
            "- pkg:\n  - /class/ana/src/pkg\n  - /class/ana/src/old/pkg\n",
            "colcon build: Duplicate package names not supported: - pkg: - src/pkg - src/old/pkg",
        ),
        (
            "running install_data\nerror: can't copy 'resource/pkg': doesn't exist or not a "
            "regular file\nFailed   <<< pkg [0.9s, exited with code 1]\n",
            "can't copy 'resource/pkg': doesn't exist or not a regular file",
        ),
        (
            'CMake Error: The source directory "/class/ana" does not appear to contain '
            "CMakeLists.txt.\n",
            'The source directory "ana" does not appear to contain CMakeLists.txt. '
            "(does package.xml say <build_type>ament_python</build_type>?)",
        ),
        (
            "Failed   <<< pkg [1.2s, exited with code 2]\n",
            "colcon: pkg failed (1.2s, exited with code 2)",
        ),
    ],
)
def test_build_error_picks_the_line_that_says_what_is_wrong(log: str, expected: str) -> None:
    """Not colcon's CalledProcessError wrapper: the student's own error, with file and line."""
    assert build_error(log, hide=(Path("/class/ana"),)) == expected


def test_check_installed_names_what_the_build_lacks(tmp_path: Path) -> None:
    """The lab's package and executable must be in the install folder, else say what is."""
    prefix = tmp_path / "install" / "other_pkg"
    (prefix / "share/ament_index/resource_index/packages").mkdir(parents=True)
    (prefix / "share/ament_index/resource_index/packages/other_pkg").touch()
    (prefix / "lib" / "other_pkg").mkdir(parents=True)
    (prefix / "lib" / "other_pkg" / "my_node").touch()
    install = tmp_path / "install"
    assert check_installed(install, "lab_pkg", "node") == (
        "package lab_pkg was not built (built: other_pkg)"
    )
    assert check_installed(install, "other_pkg", "node") == (
        "package other_pkg has no executable node (executables: my_node)"
    )
    assert check_installed(install, "other_pkg", "my_node") is None


@pytest.mark.slow
@pytest.mark.timeout(60)
def test_a_hanging_build_is_stopped_at_its_time_limit(tmp_path: Path) -> None:
    """setup.py that never returns: the build ends at --build-timeout, with that reason."""
    package = copy_package(tmp_path / "class" / "hangs")
    patch(package / "setup.py", "package_name = ", "import time\ntime.sleep(600)\npackage_name = ")
    result = build_student(
        student_in(package),
        tmp_path / "out" / "colcon",
        package="fossbot_lidar_processing",
        executable="fossbot_lidar_node",
        log=tmp_path / "out" / "build.log",
        timeout=3.0,
    )
    assert result.error == "the build took longer than 3 s (stopped)"
    assert result.wall_s < 30
