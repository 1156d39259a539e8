"""Launch files read without running them (Python, XML, YAML), and the advice they get.

Pure: no rclpy, no launch. The node's declared parameters are given as the
bundled node answers ListParameters (tests/launch_files/test_launch_files_ros.py
asks a real one).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from harness.launch_files.checks import build_problem, undeclared_parameters
from harness.launch_files.entries import LaunchFile
from harness.launch_files.finding import Workspace, package_launch_files, workspace_of
from harness.launch_files.reading import read_launch_file
from harness.launch_files.run_check import LaunchCheck
from harness.nodes.command import AMENT_MARKERS, NodeCommand, node_arguments
from harness.option_names import speaking
from harness.run_request.table import names

REPO = Path(__file__).resolve().parents[2]
LAB_LISTING = Path(__file__).parent / "lab_listing" / "lidar_node_launch.py"
BUNDLED = REPO / "node" / "fossbot_lidar_processing" / "launch" / "lidar_node_launch.py"
PACKAGE, EXECUTABLE = "fossbot_lidar_processing", "fossbot_lidar_node"
# What the bundled node answers to ListParameters (Jazzy adds the last two to every node).
DECLARED = [
    "lidar_status_topic",
    "lidar_topic",
    "scan_qos",
    "threshold",
    "warning_topic",
    "start_type_description_service",
    "use_sim_time",
]


def read(path: Path, shown: str = "launch/x") -> LaunchFile:
    found = read_launch_file(path, shown)
    assert found is not None
    return found


def written(tmp_path: Path, name: str, text: str) -> LaunchFile | None:
    path = tmp_path / name
    path.write_text(text)
    return read_launch_file(path, f"launch/{name}")


def params_of(file: LaunchFile) -> dict[str, int]:
    return {p.name: p.line for entry in file.nodes for p in entry.params}


# -- the lab's listing ---------------------------------------------------------


def test_the_lab_listing_is_told_lidar_info_topic_is_not_a_parameter_of_the_node() -> None:
    file = read(LAB_LISTING, "launch/lidar_node_launch.py")
    (entry,) = file.nodes
    assert (entry.package, entry.executable, entry.name) == (PACKAGE, EXECUTABLE, EXECUTABLE)
    line = next(
        n
        for n, text in enumerate(LAB_LISTING.read_text().splitlines(), 1)
        if "'lidar_info_topic':" in text
    )
    assert params_of(file)["lidar_info_topic"] == line
    assert undeclared_parameters(file, entry, EXECUTABLE, DECLARED) == [
        f"launch/lidar_node_launch.py line {line}: sets parameter 'lidar_info_topic', which "
        "fossbot_lidar_node does not declare (did you mean 'lidar_status_topic'? it declares "
        "lidar_status_topic, lidar_topic, scan_qos, threshold, warning_topic, use_sim_time): "
        "the node never sees it"
    ]
    assert file.unread == ()  # LaunchConfiguration values are fine: only names are checked


def test_the_bundled_launch_file_sets_only_declared_parameters() -> None:
    file = read(BUNDLED)
    (entry,) = file.nodes
    assert set(params_of(file)) == {
        "lidar_topic",
        "lidar_status_topic",
        "warning_topic",
        "threshold",
        "use_sim_time",
    }
    assert undeclared_parameters(file, entry, EXECUTABLE, DECLARED) == []
    assert {"threshold", "lidar_status_topic", "start_sim"} <= set(file.arguments)


def test_a_suggestion_is_never_a_parameter_the_entry_sets_already() -> None:
    """'lidar_topic' is closer to 'lidar_info_topic' by letters, but the file sets it."""
    file = read(LAB_LISTING)
    (entry,) = file.nodes
    (note,) = undeclared_parameters(file, entry, EXECUTABLE, DECLARED)
    assert "did you mean 'lidar_status_topic'?" in note
    (far,) = undeclared_parameters(
        file, entry, EXECUTABLE, ["lidar_topic", "warning_topic", "threshold", "use_sim_time"]
    )
    assert "did you mean" not in far
    assert "it declares lidar_topic, threshold, warning_topic, use_sim_time)" in far


# -- Python ------------------------------------------------------------------------


def test_python_imports_however_written_and_parameters_held_in_names(tmp_path: Path) -> None:
    file = written(
        tmp_path,
        "two_launch.py",
        "import launch_ros.actions as ra\n"
        "from launch_ros import actions\n"
        "from launch import LaunchDescription\n"
        "BASE = {'lidar_topic': '/scan', 'nested': {'inner': 1, 'deeper': {'x': 2}}}\n"
        "ALL = [BASE, {'threshold': 0.4}]\n"
        "def generate_launch_description():\n"
        "    first = ra.Node(package='p', executable='a', parameters=ALL)\n"
        "    second = actions.Node(package='p', node_executable='b', node_name='bee',\n"
        "                          parameters=[{'warning_topic': '/w'}])\n"
        "    return LaunchDescription([first, second])\n",
    )
    assert file is not None
    first, second = file.nodes
    assert (first.package, first.executable, first.line) == ("p", "a", 7)
    assert {p.name: p.line for p in first.params} == {
        "lidar_topic": 4,
        "nested.inner": 4,
        "nested.deeper.x": 4,
        "threshold": 5,
    }
    assert (second.executable, second.name) == ("b", "bee")
    assert [p.name for p in second.params] == ["warning_topic"]
    assert file.unread == ()


def test_python_what_is_known_only_when_the_file_runs_is_said_not_guessed(tmp_path: Path) -> None:
    file = written(
        tmp_path,
        "dynamic_launch.py",
        "import os\n"
        "from launch_ros.actions import Node as N\n"
        "from launch.substitutions import LaunchConfiguration\n"
        "extra = {'a': 1}\n"
        "extra['b'] = 2\n"
        "def generate_launch_description():\n"
        "    return [\n"
        "        N(package=LaunchConfiguration('pkg'), executable='e'),\n"
        "        N(package='p', executable='e', parameters=[\n"
        "            os.path.join('config', 'params.yaml'),\n"
        "            extra,\n"
        "            {'ok': 1, **extra},\n"
        "        ]),\n"
        "        N(package='p', executable='e', parameters=make()),\n"
        "    ]\n",
    )
    assert file is not None
    assert [(u.line, u.what.split(" ")[0]) for u in file.unread] == [
        (8, "package=LaunchConfiguration('pkg')"),
        (10, "parameters"),  # a parameter file
        (11, "parameters"),  # a name changed after it was made
        (12, "**extra"),
        (14, "parameters=make()"),
    ]
    assert "known only when the file runs" in file.unread[0].what
    assert file.nodes[0].package is None
    assert [p.name for p in file.nodes[1].params] == ["ok"]


def test_python_files_that_are_no_launch_file_or_do_not_parse(tmp_path: Path) -> None:
    assert written(tmp_path, "helpers.py", "def nodes():\n    return []\n") is None
    broken = written(tmp_path, "broken_launch.py", "def generate_launch_description(:\n")
    assert broken is not None and broken.nodes == ()
    (problem,) = broken.unread
    assert problem.line == 1 and problem.what.startswith("does not parse as Python")
    other = written(
        tmp_path,
        "other_launch.py",
        "from my_tools import Node\n"
        "def generate_launch_description():\n"
        "    return [Node(package='p', executable='e')]\n",
    )
    assert other is not None and other.nodes == ()  # not launch_ros's Node


# -- XML and YAML ------------------------------------------------------------------

XML = """<?xml version="1.0"?>
<launch>
  <arg name="threshold" default="0.5"/>
  <group>
    <node pkg="fossbot_lidar_processing" exec="fossbot_lidar_node" name="lidar">
      <param name="lidar_info_topic" value="/lidar_status"/>
      <param name="threshold" value="$(var threshold)"/>
      <param name="limits">
        <param name="low" value="0.1"/>
      </param>
      <param from="$(find-pkg-share fossbot_lidar_processing)/config/params.yaml"/>
    </node>
  </group>
  <node pkg="p" exec="$(var which)"/>
  <node pkg="p" type="ros1_node"/>
</launch>
"""

YAML = """launch:
- arg:
    name: threshold
    default: "0.5"
- group:
    children:
    - node:
        pkg: fossbot_lidar_processing
        exec: fossbot_lidar_node
        name: lidar
        param:
        - name: lidar_info_topic
          value: /lidar_status
        - name: threshold
          value: $(var threshold)
        - name: limits
          param:
          - name: low
            value: 0.1
        - from: $(find-pkg-share fossbot_lidar_processing)/config/params.yaml
- node:
    pkg: p
    exec: $(var which)
"""


@pytest.mark.parametrize(
    ("name", "text", "lines"),
    [
        ("lidar.launch.xml", XML, {"lidar_info_topic": 6, "threshold": 7, "limits.low": 9}),
        ("lidar.launch.yaml", YAML, {"lidar_info_topic": 12, "threshold": 14, "limits.low": 18}),
    ],
)
def test_xml_and_yaml_nodes_parameters_and_arguments(
    tmp_path: Path, name: str, text: str, lines: dict[str, int]
) -> None:
    file = written(tmp_path, name, text)
    assert file is not None
    assert file.arguments == ("threshold",)
    first = file.nodes[0]
    assert (first.package, first.executable, first.name) == (PACKAGE, EXECUTABLE, "lidar")
    assert {p.name: p.line for p in first.params} == lines
    assert file.nodes[1].executable is None  # $(var which)
    whats = [u.what for u in file.unread]
    assert any(w.startswith("parameters from '$(find-pkg-share") for w in whats)
    assert any(w.startswith("exec='$(var which)' is known only when the file runs") for w in whats)
    note, nested = undeclared_parameters(file, first, "lidar", DECLARED)
    assert nested.startswith(
        f"launch/{name} line {lines['limits.low']}: sets parameter 'limits.low'"
    )
    assert (
        f"launch/{name} line {lines['lidar_info_topic']}: sets parameter 'lidar_info_topic'" in note
    )
    assert "did you mean 'lidar_topic' or 'lidar_status_topic'?" in note  # it sets neither


def test_xml_ros1_type_and_refused_or_broken_files(tmp_path: Path) -> None:
    file = written(tmp_path, "lidar.launch.xml", XML)
    assert file is not None
    assert any("type= is ROS 1's name" in u.what and u.line == 15 for u in file.unread)
    entity = '<?xml version="1.0"?>\n<!DOCTYPE launch [<!ENTITY a "aaaa">]>\n<launch/>\n'
    refused = written(tmp_path, "bomb.launch.xml", entity)
    assert refused is not None and "document type declaration" in refused.unread[0].what
    broken = written(tmp_path, "broken.launch.xml", "<launch>\n  <node pkg='p'\n</launch>\n")
    assert broken is not None and broken.unread[0].what.startswith("does not parse as XML")
    assert written(tmp_path, "other.xml", "<package><name>p</name></package>") is None


def test_yaml_aliases_are_walked_once_and_other_yaml_is_no_launch_file(tmp_path: Path) -> None:
    shared = (
        "launch:\n"
        "- node: &n\n    pkg: p\n    exec: e\n    param: [{name: a, value: 1}]\n"
        "- node: *n\n"
    )
    file = written(tmp_path, "alias.launch.yaml", shared)
    assert file is not None and len(file.nodes) == 1
    assert written(tmp_path, "params.yaml", "node:\n  ros__parameters:\n    a: 1\n") is None
    broken = written(tmp_path, "broken.launch.yaml", "launch:\n- node: [\n")
    assert broken is not None and broken.unread[0].what.startswith("does not parse as YAML")


# -- a workspace: the source launch/ folder, the install, the build ---------------------


def workspace(tmp_path: Path, *, installed_launch: str | None) -> Path:
    """A colcon workspace's files (what a build leaves): src/ with the lab listing, an
    isolated install/ with the package's marker, its executable and (maybe) the
    launch file's installed copy."""
    root = tmp_path / "ws"
    source = root / "src" / PACKAGE
    (source / "launch").mkdir(parents=True)
    (source / "package.xml").write_text(f"<package><name>{PACKAGE}</name></package>\n")
    shutil.copy(LAB_LISTING, source / "launch" / LAB_LISTING.name)
    prefix = root / "install" / PACKAGE
    (prefix / AMENT_MARKERS).mkdir(parents=True)
    (prefix / AMENT_MARKERS / PACKAGE).write_text("")
    (prefix / "lib" / PACKAGE).mkdir(parents=True)
    (prefix / "lib" / PACKAGE / EXECUTABLE).write_text("#!/bin/sh\n")
    (prefix / "share" / PACKAGE / "launch").mkdir(parents=True)
    if installed_launch is not None:
        (prefix / "share" / PACKAGE / "launch" / LAB_LISTING.name).write_text(installed_launch)
    return root


def test_source_launch_files_come_first_and_the_install_is_compared(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=LAB_LISTING.read_text())
    found = package_launch_files(PACKAGE, workspace_of(str(root)))
    assert [shown for _, shown in found.files] == ["launch/lidar_node_launch.py"]
    assert found.from_source
    check = LaunchCheck.for_run(PACKAGE, EXECUTABLE, str(root))
    assert check is not None and check.static == ()

    stale = workspace(tmp_path / "stale", installed_launch="# an older copy\n")
    check = LaunchCheck.for_run(PACKAGE, EXECUTABLE, str(stale))
    assert check is not None
    assert check.static == (
        "launch/lidar_node_launch.py differs from its installed copy, which is what "
        "`ros2 launch` runs: rebuild (colcon build) to install it",
    )
    missing = workspace(tmp_path / "missing", installed_launch=None)
    check = LaunchCheck.for_run(PACKAGE, EXECUTABLE, str(missing))
    assert check is not None
    (note,) = check.static
    assert note.startswith("launch/lidar_node_launch.py is not installed")


def test_only_the_install_when_there_are_no_sources(tmp_path: Path) -> None:
    """A grader's scratch workspace holds install/ only: the installed files are read."""
    root = workspace(tmp_path, installed_launch=LAB_LISTING.read_text())
    shutil.rmtree(root / "src")
    found = package_launch_files(PACKAGE, workspace_of(str(root)))
    assert [shown for _, shown in found.files] == [f"share/{PACKAGE}/launch/lidar_node_launch.py"]


def test_a_node_the_build_cannot_start_is_named(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=None)
    space = workspace_of(str(root))
    file = written(
        tmp_path,
        "wrong_launch.py",
        "from launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return [Node(package='fossbot_lidar_processing', executable='lidar_node'),\n"
        "            Node(package='fossbot_lidar', executable='x')]\n",
    )
    assert file is not None
    first, second = file.nodes
    assert build_problem(file, first, space, "the workspace") == (
        "launch/wrong_launch.py line 3: starts executable 'lidar_node' of "
        "fossbot_lidar_processing, which its build does not install (lib/fossbot_lidar_processing "
        "has: fossbot_lidar_node): `ros2 launch` cannot start that node"
    )
    assert build_problem(file, second, space, "the workspace") == (
        "launch/wrong_launch.py line 4: starts package 'fossbot_lidar', which is not in the "
        "workspace: `ros2 launch` cannot start that node"
    )
    assert build_problem(file, first, Workspace(None, ()), "AMENT_PREFIX_PATH") is not None


def test_the_node_is_asked_once_a_run_and_a_failed_question_is_said(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=LAB_LISTING.read_text())
    check = LaunchCheck.for_run(PACKAGE, EXECUTABLE, str(root))
    assert check is not None
    asked: list[int] = []

    def ask() -> tuple[str, list[str]]:
        asked.append(1)
        return EXECUTABLE, DECLARED

    assert check.notes(None) == []  # the node is not up: nothing asked yet
    (note,) = check.notes(ask)
    assert "'lidar_info_topic', which fossbot_lidar_node does not declare" in note
    assert check.notes(ask) == [note] and asked == [1]

    other = LaunchCheck.for_run(PACKAGE, EXECUTABLE, str(root))
    assert other is not None
    assert other.notes(lambda: "no node publishes /lidar_status") == [
        "launch/lidar_node_launch.py: parameters not checked against the node: no node "
        "publishes /lidar_status"
    ]
    assert LaunchCheck.for_run(PACKAGE, "other_executable", str(root)) is not None
    assert LaunchCheck.for_run("no_such_package", EXECUTABLE, str(root)) is None


def test_launch_arguments_take_the_parameters_the_file_declares() -> None:
    launch = NodeCommand(
        ("ros2", "launch", PACKAGE, "x.py"),
        launch_arguments=frozenset({"threshold", "use_sim_time"}),
    )
    params = ("threshold:=0.4", "lidar_status_topic:=/s")
    assert node_arguments(launch, params) == ["use_sim_time:=true", "threshold:=0.4"]
    plain = NodeCommand(("node",))
    assert node_arguments(plain, params) == [
        "--ros-args",
        "-p",
        "use_sim_time:=true",
        "-p",
        "threshold:=0.4",
        "-p",
        "lidar_status_topic:=/s",
    ]


def test_launch_arguments_the_file_lacks_are_named(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=LAB_LISTING.read_text())
    passed = ["use_sim_time", "threshold", "lidar_status_topic"]
    with speaking(names("cli")):  # the notes name the options as the caller does
        check = LaunchCheck.for_run(
            PACKAGE, None, str(root), launched=LAB_LISTING.name, passed=passed
        )
    assert check is not None
    assert check.static == (
        "--launch: launch/lidar_node_launch.py declares no launch argument 'lidar_status_topic', "
        "so the harness cannot pass lidar_status_topic to the node through it (the node keeps "
        "the file's value)",
    )
    *_, note = check.notes(lambda: (EXECUTABLE, DECLARED))  # the entry named as the node
    assert "sets parameter 'lidar_info_topic'" in note


# -- run --launch where `ros2 launch` is not installed ----------------------------------


def without_ros2() -> dict[str, str]:
    """The environment with a PATH that has no ros2 (this machine's has none either)."""
    path = os.pathsep.join([str(Path(sys.executable).parent), "/usr/bin", "/bin"])
    if shutil.which("ros2", path=path) is not None:
        pytest.skip("ros2 is installed in /usr/bin here")
    return {**os.environ, "PATH": path}


def fossbot_hil_run(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "harness.cli", "run", *args]
    return subprocess.run(
        command, capture_output=True, text=True, timeout=120, env=without_ros2(), check=False
    )


def test_launch_without_ros2_reads_the_file_then_says_what_to_do(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=None)
    (root / "src" / PACKAGE / "launch" / "wrong_launch.py").write_text(
        "from launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return [Node(package='fossbot_lidar_processing', executable='lidar_node',\n"
        "                 parameters=[{'lidar_info_topic': '/s'}])]\n"
    )
    done = fossbot_hil_run("--launch", PACKAGE, "wrong_launch.py", "--workspace", str(root))
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stdout.splitlines() == [
        "note: launch/wrong_launch.py is not installed (the build's share/fossbot_lidar_processing/"
        "launch has no wrong_launch.py): `ros2 launch fossbot_lidar_processing wrong_launch.py` "
        "does not find it; install it (data_files in setup.py) and rebuild",
        "note: launch/wrong_launch.py line 3: starts executable 'lidar_node' of "
        "fossbot_lidar_processing, which its build does not install (lib/fossbot_lidar_processing "
        "has: fossbot_lidar_node): `ros2 launch` cannot start that node",
    ]
    (error,) = done.stderr.splitlines()
    assert error.startswith(
        "fossbot-hil: error: --launch fossbot_lidar_processing wrong_launch.py: `ros2 launch` is "
        "not installed here (no ros2 on PATH); source a ROS 2 installation"
    )
    assert "--workspace DIR --package P --executable E" in error


def test_launch_usage_errors_exit_2_in_one_line(tmp_path: Path) -> None:
    root = workspace(tmp_path, installed_launch=None)
    unknown = fossbot_hil_run("--launch", PACKAGE, "nothing.py", "--workspace", str(root))
    assert unknown.returncode == 2
    assert unknown.stderr.strip() == (
        "fossbot-hil: error: --launch fossbot_lidar_processing nothing.py: "
        "fossbot_lidar_processing has no launch file nothing.py (its launch files: "
        "lidar_node_launch.py)"
    )
    both = fossbot_hil_run("--launch", PACKAGE, "lidar_node_launch.py", "--package", PACKAGE)
    assert both.returncode == 2
    assert both.stderr.strip() == (
        "fossbot-hil: error: --launch starts the node itself: drop --node/--package/--executable"
    )
