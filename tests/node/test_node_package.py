"""The ament_python package's files: setup.py, setup.cfg, package.xml, the launch file.

The launch file imports `launch`/`launch_ros`, which exist only on a real
ROS install, so it is checked statically (with `ast`) everywhere and loaded
for real only where those packages import.
"""

from __future__ import annotations

import ast
import configparser
import importlib.util
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "node" / "fossbot_lidar_processing"
LAUNCH_FILE = PACKAGE / "launch" / "lidar_node_launch.py"
NODE_SOURCE = PACKAGE / "fossbot_lidar_processing" / "lidar_node.py"
LAUNCH_ARGUMENTS = {"lidar_topic", "lidar_status_topic", "warning_topic", "threshold"}


def calls(tree: ast.AST, name: str) -> list[ast.Call]:
    """Every call of `name(...)` (or `x.name(...)`) in the tree."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            called = func.id if isinstance(func, ast.Name) else getattr(func, "attr", None)
            if called == name:
                found.append(node)
    return found


def first_string(call: ast.Call, keyword: str) -> str | None:
    """The call's first positional argument or `keyword=`, if a string literal."""
    candidates = [*call.args[:1], *(k.value for k in call.keywords if k.arg == keyword)]
    for value in candidates:
        if isinstance(value, ast.Constant) and isinstance(value.value, str):
            return value.value
    return None


def keyword_string(call: ast.Call, keyword: str) -> str | None:
    """The string literal passed as `keyword=`, if any."""
    for k in call.keywords:
        if k.arg == keyword and isinstance(k.value, ast.Constant):
            return k.value.value
    return None


@pytest.fixture(scope="module")
def launch_tree() -> ast.Module:
    """The launch file's syntax tree."""
    return ast.parse(LAUNCH_FILE.read_text(), filename=str(LAUNCH_FILE))


def declared_arguments(tree: ast.Module) -> set[str]:
    """Names of the launch arguments declared with DeclareLaunchArgument."""
    return {first_string(c, "name") for c in calls(tree, "DeclareLaunchArgument")} - {None}


def node_call(tree: ast.Module) -> ast.Call:
    """The launch_ros Node(...) action (exactly one)."""
    (node,) = calls(tree, "Node")
    return node


def node_parameters(tree: ast.Module) -> dict[str, ast.expr]:
    """The parameters dict passed to the Node action, keyed by parameter name."""
    (parameters,) = [k.value for k in node_call(tree).keywords if k.arg == "parameters"]
    assert isinstance(parameters, ast.List)
    (mapping,) = [e for e in parameters.elts if isinstance(e, ast.Dict)]
    return {key.value: value for key, value in zip(mapping.keys, mapping.values, strict=True)}


def test_launch_declares_the_labs_arguments(launch_tree) -> None:
    """lidar_topic, lidar_status_topic, warning_topic and threshold are launch arguments."""
    assert LAUNCH_ARGUMENTS | {"use_sim_time", "start_sim"} <= declared_arguments(launch_tree)


def test_launch_passes_lidar_status_topic_not_lidar_info_topic(launch_tree) -> None:
    """The lab's defect: the launch file must pass the parameter the node declares."""
    parameters = node_parameters(launch_tree)
    assert "lidar_status_topic" in parameters
    assert "lidar_info_topic" not in parameters
    strings = {n.value for n in ast.walk(launch_tree) if isinstance(n, ast.Constant)}
    assert "lidar_info_topic" not in strings


def test_each_node_parameter_comes_from_the_argument_of_its_name(launch_tree) -> None:
    """`threshold` is fed by LaunchConfiguration('threshold'), and so on for each one."""
    parameters = node_parameters(launch_tree)
    assert LAUNCH_ARGUMENTS | {"use_sim_time"} <= set(parameters)
    for name, value in parameters.items():
        sources = {first_string(c, "variable_name") for c in calls(value, "LaunchConfiguration")}
        assert sources == {name}, f"parameter {name} is fed by {sources}"


def test_launch_parameters_are_declared_by_the_node(launch_tree) -> None:
    """Every parameter the launch file sets is one the node declares (else ROS drops it)."""
    node_tree = ast.parse(NODE_SOURCE.read_text())
    declared = {first_string(c, "name") for c in calls(node_tree, "declare_parameter")}
    declared.add("use_sim_time")  # declared by every rclpy Node
    assert set(node_parameters(launch_tree)) <= declared


def test_every_launch_configuration_is_declared(launch_tree) -> None:
    """A LaunchConfiguration of an undeclared argument would fail at launch time."""
    used = {first_string(c, "variable_name") for c in calls(launch_tree, "LaunchConfiguration")}
    assert used <= declared_arguments(launch_tree)


def test_launch_starts_the_right_executable(launch_tree) -> None:
    """The Node action names this package and its console script."""
    node = node_call(launch_tree)
    assert keyword_string(node, "package") == "fossbot_lidar_processing"
    assert keyword_string(node, "executable") == "fossbot_lidar_node"


def test_simulator_is_optional_and_off_by_default(launch_tree) -> None:
    """start_sim (default false) gates the lab's Gazebo world through an IfCondition."""
    (include,) = calls(launch_tree, "IncludeLaunchDescription")
    (condition,) = [k.value for k in include.keywords if k.arg == "condition"]
    assert isinstance(condition, ast.Call) and condition.func.id == "IfCondition"
    gate = {first_string(c, "variable_name") for c in calls(condition, "LaunchConfiguration")}
    assert gate == {"start_sim"}
    defaults = {
        first_string(c, "name"): keyword_string(c, "default_value")
        for c in calls(launch_tree, "DeclareLaunchArgument")
    }
    assert defaults["start_sim"] == "false"
    assert defaults["world"] == "single_wall.sdf"
    strings = {n.value for n in ast.walk(include) if isinstance(n, ast.Constant)}
    assert {"fossbot_educational_description", "single.launch.py"} <= strings


def test_launch_file_loads_with_real_launch_packages() -> None:
    """Where ROS 2's launch and launch_ros import, the description builds and lists the args."""
    pytest.importorskip("launch_ros", reason="launch_ros is only on a real ROS 2 install")
    pytest.importorskip("launch", reason="launch is only on a real ROS 2 install")
    spec = importlib.util.spec_from_file_location("lidar_node_launch", LAUNCH_FILE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    names = {argument.name for argument in description.get_launch_arguments()}
    assert LAUNCH_ARGUMENTS | {"use_sim_time", "start_sim"} <= names


@pytest.fixture(scope="module")
def setup_tree() -> ast.Module:
    """setup.py's syntax tree."""
    return ast.parse((PACKAGE / "setup.py").read_text())


def test_setup_has_no_glob_glob_defect(setup_tree) -> None:
    """The lab's defect: `from glob import glob` then `glob.glob(...)`."""
    glob_glob = [
        n
        for n in ast.walk(setup_tree)
        if isinstance(n, ast.Attribute)
        and n.attr == "glob"
        and isinstance(n.value, ast.Name)
        and n.value.id == "glob"
    ]
    assert not glob_glob, "setup.py calls glob.glob"


def test_setup_entry_point_names_the_node(setup_tree) -> None:
    """The console script `fossbot_lidar_node` runs lidar_node.main."""
    scripts = [
        n.value
        for n in ast.walk(setup_tree)
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and "=" in n.value
    ]
    entries = {s.split("=")[0].strip(): s.split("=")[1].strip() for s in scripts}
    assert entries.get("fossbot_lidar_node") == "fossbot_lidar_processing.lidar_node:main"


def test_setup_py_runs() -> None:
    """setup.py evaluates (the glob.glob defect failed right here) and names the package."""
    result = subprocess.run(
        [sys.executable, "setup.py", "--name", "--version"],
        cwd=PACKAGE,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split()[-2:] == ["fossbot_lidar_processing", "0.1.0"]


def test_setup_cfg_installs_scripts_where_ros2_run_looks() -> None:
    """`ros2 run` finds executables in lib/<package>, which setup.cfg selects."""
    config = configparser.ConfigParser(interpolation=None)
    config.read(PACKAGE / "setup.cfg")
    assert config["develop"]["script_dir"] == "$base/lib/fossbot_lidar_processing"
    assert config["install"]["install_scripts"] == "$base/lib/fossbot_lidar_processing"


def test_package_xml() -> None:
    """Format 3, ament_python, the runtime dependencies, and setup.py's version."""
    root = ET.parse(PACKAGE / "package.xml").getroot()
    assert root.get("format") == "3"
    assert root.findtext("name") == "fossbot_lidar_processing"
    assert root.findtext("export/build_type") == "ament_python"
    exec_depends = {e.text for e in root.iter("exec_depend")}
    assert {
        "rclpy",
        "sensor_msgs",
        "std_msgs",
        "python3-numpy",
        "launch",
        "launch_ros",
    } <= exec_depends
    assert f"version='{root.findtext('version')}'" in (PACKAGE / "setup.py").read_text()


def test_resource_marker_and_standard_tests_exist() -> None:
    """The ament index marker and the files `ros2 pkg create` generates are present."""
    assert (PACKAGE / "resource" / "fossbot_lidar_processing").is_file()
    for name in ("test_copyright.py", "test_flake8.py", "test_pep257.py", "test_scan_logic.py"):
        assert (PACKAGE / "test" / name).is_file()


def test_package_tests_pass_with_plain_pytest() -> None:
    """The package's own test/ (logic and ament linters) passes under plain pytest."""
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test"],
        cwd=PACKAGE,
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    assert "failed" not in result.stdout.splitlines()[-1]
