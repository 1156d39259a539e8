"""The package builds with colcon (PyPI `colcon-common-extensions`) into the layout `ros2 run` uses.

Skipped where colcon (with its ROS extension) is not installed.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sysconfig
from pathlib import Path

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.timeout(120)]

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "fossbot_lidar_processing"


def colcon(*args: str, base: Path) -> subprocess.CompletedProcess[str]:
    """Run colcon on the node/ folder only, with every output under `base`."""
    command = [
        shutil.which("colcon") or "colcon",
        "--log-base",
        str(base / "log"),
        *args,
        "--base-paths",
        "node",
        "--packages-select",
        PACKAGE,
        "--build-base",
        str(base / "build"),
        "--install-base",
        str(base / "install"),
    ]
    return subprocess.run(
        command, cwd=REPO, capture_output=True, text=True, timeout=100, check=False
    )


@pytest.fixture(scope="module")
def colcon_install(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`colcon build` of the package into a temporary workspace; returns its install prefix."""
    if shutil.which("colcon") is None:
        pytest.skip("colcon is not installed (pip install colcon-common-extensions)")
    pytest.importorskip("colcon_ros", reason="colcon-ros (builds ament_python) not installed")
    base = tmp_path_factory.mktemp("colcon")
    result = colcon("build", base=base)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return base / "install" / PACKAGE


def site_packages(prefix: Path) -> Path:
    """The install's site-packages, which colcon's setup scripts put on PYTHONPATH."""
    relative = Path(sysconfig.get_path("purelib")).relative_to(sysconfig.get_path("data"))
    return prefix / relative


def test_build_installs_what_ros2_run_needs(colcon_install: Path) -> None:
    """The ament index marker, the executable in lib/<pkg>, the launch file and package.xml."""
    marker = colcon_install / "share/ament_index/resource_index/packages" / PACKAGE
    executable = colcon_install / "lib" / PACKAGE / "fossbot_lidar_node"
    assert marker.is_file()
    assert executable.is_file() and os.access(executable, os.X_OK)
    assert (colcon_install / "share" / PACKAGE / "launch" / "lidar_node_launch.py").is_file()
    assert (colcon_install / "share" / PACKAGE / "package.xml").is_file()
    assert (site_packages(colcon_install) / PACKAGE / "scan_logic.py").is_file()


def test_ament_index_resolves_the_package(
    colcon_install: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """ament_index_python (what `ros2 run` uses) finds the package in the install."""
    packages = pytest.importorskip("ament_index_python.packages")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(colcon_install))
    prefix = Path(packages.get_package_prefix(PACKAGE))
    assert (prefix / "lib" / PACKAGE / "fossbot_lidar_node").is_file()


@pytest.mark.ros
def test_installed_executable_answers_a_scan(
    colcon_install: Path, start_node, ros_graph, make_scan_fn
) -> None:
    """The console script, run as the setup scripts would, answers and stops on SIGTERM."""
    pythonpath = os.pathsep.join(
        p for p in (str(site_packages(colcon_install)), os.environ.get("PYTHONPATH")) if p
    )
    node = start_node(
        "-p",
        "threshold:=0.4",
        command=[str(colcon_install / "lib" / PACKAGE / "fossbot_lidar_node")],
        extra_env={"PYTHONPATH": pythonpath, "AMENT_PREFIX_PATH": str(colcon_install)},
    )
    graph = ros_graph()
    graph.handshake(node)
    answer = graph.ask(make_scan_fn([0.3, 2.0]))
    assert (answer.status, answer.warning) == ("Min distance: 0.300 m, angle: -3.142 rad", True)
    assert node.stop() == 0
    assert "Traceback" not in node.stderr()


def test_colcon_test_runs_the_package_tests(colcon_install: Path) -> None:
    """`colcon test` runs test/ (linters and unit tests) and `colcon test-result` is clean."""
    base = colcon_install.parent.parent
    results = base / "test_results"
    tested = colcon("test", "--test-result-base", str(results), base=base)
    assert tested.returncode == 0, tested.stdout[-3000:] + tested.stderr[-3000:]
    summary = subprocess.run(
        [shutil.which("colcon") or "colcon", "test-result", "--test-result-base", str(results)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert summary.returncode == 0, summary.stdout + summary.stderr
    assert "0 failures" in summary.stdout and "0 errors" in summary.stdout


def test_source_tree_stays_clean(colcon_install: Path) -> None:
    """Building leaves no egg-info or build output next to the sources (the harness ships them)."""
    package_dir = REPO / "node" / PACKAGE
    leftovers = [
        p.name
        for p in package_dir.iterdir()
        if p.name.endswith(".egg-info") or p.name in ("build", "install", "log")
    ]
    assert leftovers == []
