"""A workspace's launch file held against the running node: `fossbot-hil run --workspace`.

Real parts: the lab's package built by colcon with the lab's own launch
listing (which passes `lidar_info_topic`), the node started from the
workspace, and its declared parameters asked over ListParameters in the
run's ROS graph. The advice never fails a scenario.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from harness.bench.lab_workspace import build_lab_workspace, colcon_program, lab_package_source

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]

PACKAGE, EXECUTABLE = "fossbot_lidar_processing", "fossbot_lidar_node"
LAB_LISTING = Path(__file__).parent / "lab_listing" / "lidar_node_launch.py"
BUILD_TIMEOUT_S = 180


def lab_listing_line() -> int:
    text = LAB_LISTING.read_text().splitlines()
    return next(n for n, line in enumerate(text, 1) if "'lidar_info_topic':" in line)


@pytest.fixture(scope="module")
def lab_workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The lab's package with the lab's launch listing, built as a student's workspace."""
    source = tmp_path_factory.mktemp("lab") / PACKAGE
    shutil.copytree(
        lab_package_source(), source, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info")
    )
    shutil.copy(LAB_LISTING, source / "launch" / LAB_LISTING.name)
    root = tmp_path_factory.mktemp("ws") / "ws"
    return build_lab_workspace(root, source, colcon_program(), timeout=BUILD_TIMEOUT_S).root


def use_launch_file(workspace: Path, launch_file: Path) -> None:
    """Put `launch_file` in the package's source folder and its installed copy, as a
    rebuild leaves it (colcon copies launch files as they are): each test says which
    it runs with, whatever ran before it on this workspace."""
    for folder in (
        workspace / "src" / PACKAGE / "launch",
        workspace / "install" / PACKAGE / "share" / PACKAGE / "launch",
    ):
        shutil.copy(launch_file, folder / LAB_LISTING.name)


def run(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "harness.cli", "run", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=180, check=False)


def test_run_tells_the_lab_listing_passes_a_parameter_the_node_does_not_declare(
    lab_workspace: Path, tmp_path: Path
) -> None:
    use_launch_file(lab_workspace, LAB_LISTING)
    out = tmp_path / "report"
    done = run(
        "approach_wall",
        "out_of_range",
        "--workspace",
        str(lab_workspace),
        "--package",
        PACKAGE,
        "--executable",
        EXECUTABLE,
        "--out",
        str(out),
    )
    assert done.returncode == 0, done.stdout + done.stderr  # advice: the scenarios pass
    expected = (
        f"launch/lidar_node_launch.py line {lab_listing_line()}: sets parameter "
        "'lidar_info_topic', which fossbot_lidar_node does not declare (did you mean "
        "'lidar_status_topic'? it declares lidar_status_topic, lidar_topic, scan_qos, "
        "threshold, warning_topic, use_sim_time): the node never sees it"
    )
    notes = [line for line in done.stdout.splitlines() if line.startswith("note: ")]
    assert notes == [f"note: {expected}"], done.stdout  # once for the run
    summary = json.loads((out / "summary.json").read_text())
    assert summary["notes"] == [expected]
    assert all(entry["notes"] == [expected] for entry in summary["scenarios"])
    assert "sets parameter &#x27;lidar_info_topic&#x27;" in (out / "index.html").read_text()


def test_the_fixed_launch_file_says_nothing(lab_workspace: Path) -> None:
    """The bundled package's launch file: the lab's, fixed."""
    use_launch_file(lab_workspace, lab_package_source() / "launch" / LAB_LISTING.name)
    done = run(
        "approach_wall",
        "--workspace",
        str(lab_workspace),
        "--package",
        PACKAGE,
        "--executable",
        EXECUTABLE,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "note:" not in done.stdout, done.stdout


def ros2_stand_in(folder: Path, workspace: Path, log: Path) -> Path:
    """A `ros2` with a launch verb that starts the package's installed node with the
    launch arguments as its parameters, logging what it was given: `ros2 launch` is
    not on the package index, so this machine has none (the real one is used wherever
    ROS 2 is sourced)."""
    program = folder / "ros2"
    node = workspace / "install" / PACKAGE / "lib" / PACKAGE / EXECUTABLE
    program.write_text(
        f"#!{sys.executable}\n"
        "import os, sys\n"
        "args = sys.argv[1:]\n"
        "if args[:2] == ['launch', '--help']:\n"
        "    sys.exit(0)\n"
        f"with open({str(log)!r}, 'a') as handle:\n"
        "    handle.write(' '.join(args) + '\\n')\n"
        "parameters = [word for item in args[3:] for word in ('-p', item)]\n"
        f"os.execv({str(node)!r}, [{str(node)!r}, '--ros-args', *parameters])\n"
    )
    program.chmod(0o755)
    return program


def test_launch_starts_the_node_through_ros2_launch_with_the_harness_parameters(
    lab_workspace: Path, tmp_path: Path
) -> None:
    """--launch PACKAGE FILE: the node is `ros2 launch PACKAGE FILE` with the harness's
    parameters as the launch arguments the file declares (threshold, use_sim_time)."""
    use_launch_file(lab_workspace, lab_package_source() / "launch" / LAB_LISTING.name)
    bin_folder = tmp_path / "bin"
    bin_folder.mkdir()
    log = tmp_path / "ros2_launch.log"
    ros2_stand_in(bin_folder, lab_workspace, log)
    command = [sys.executable, "-m", "harness.cli", "run", "approach_wall", "--threshold", "0.4"]
    command += ["--workspace", str(lab_workspace), "--launch", PACKAGE, LAB_LISTING.name]
    environment = {**os.environ, "PATH": f"{bin_folder}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run(
        command, capture_output=True, text=True, timeout=180, check=False, env=environment
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 of 1 scenario passed" in done.stdout, done.stdout
    assert f"node: ros2 launch {PACKAGE} {LAB_LISTING.name}" in done.stdout, done.stdout
    launched = log.read_text().split()
    assert launched[:3] == ["launch", PACKAGE, LAB_LISTING.name], launched
    assert {"use_sim_time:=true", "threshold:=0.4"} <= set(launched[3:]), launched
    assert "note:" not in done.stdout, done.stdout
