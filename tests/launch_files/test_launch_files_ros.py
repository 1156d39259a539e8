"""A workspace's launch file held against the running node: `fossbot-hil run --workspace`.

Real parts: the lab's package built by colcon with the lab's own launch
listing (which passes `lidar_info_topic`), the node started from the
workspace, and its declared parameters asked over ListParameters in the
run's ROS graph. The advice never fails a scenario.
"""

from __future__ import annotations

import json
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
