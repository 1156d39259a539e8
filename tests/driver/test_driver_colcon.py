"""The driver package builds with colcon into the layout `ros2 run` uses, and its tests pass.

Skipped where colcon (with its ROS extension) is not installed.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sysconfig
from pathlib import Path

import pytest
from driver_wire import BURST_PERIOD, LdStreamer, burst

pytestmark = [pytest.mark.slow, pytest.mark.timeout(180)]

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "fossbot_lidar_driver"
EXECUTABLES = ("rplidar_node", "ldlidar_node")


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
        command, cwd=REPO, capture_output=True, text=True, timeout=150, check=False
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


def test_build_installs_both_executables(colcon_install: Path) -> None:
    """The ament index marker, lib/<pkg>/{rplidar_node,ldlidar_node}, package.xml, modules."""
    marker = colcon_install / "share/ament_index/resource_index/packages" / PACKAGE
    assert marker.is_file()
    for name in EXECUTABLES:
        executable = colcon_install / "lib" / PACKAGE / name
        assert executable.is_file() and os.access(executable, os.X_OK)
    assert (colcon_install / "share" / PACKAGE / "package.xml").is_file()
    assert (site_packages(colcon_install) / PACKAGE / "ld_protocol.py").is_file()


@pytest.mark.ros
def test_installed_rplidar_node_reports_a_missing_port(colcon_install: Path, start_driver) -> None:
    """The console script starts (its requirements resolve) and exits 2 on a missing port."""
    driver = start_driver(
        "rplidar_node",
        "-p",
        "port:=/dev/fossbot-hil-no-such-tty",
        command=[str(colcon_install / "lib" / PACKAGE / "rplidar_node")],
        package_path=site_packages(colcon_install),
    )
    assert driver.wait() == 2
    assert "cannot open /dev/fossbot-hil-no-such-tty" in driver.stderr()


@pytest.mark.ros
def test_installed_ldlidar_node_publishes(
    colcon_install: Path, pty, start_driver, scan_probe
) -> None:
    """The installed LD driver turns a pty stream into scans and stops on SIGTERM."""
    LdStreamer(pty, burst, BURST_PERIOD).start()
    driver = start_driver(
        "ldlidar_node",
        "-p",
        f"port:={pty.name}",
        command=[str(colcon_install / "lib" / PACKAGE / "ldlidar_node")],
        package_path=site_packages(colcon_install),
    )
    scan = scan_probe().wait_scans(1, driver)[0]
    assert len(scan.ranges) == 450
    assert driver.stop() == 0


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
    """Building leaves no egg-info or build output next to the sources."""
    package_dir = REPO / "node" / PACKAGE
    leftovers = [
        p.name
        for p in package_dir.iterdir()
        if p.name.endswith(".egg-info") or p.name in ("build", "install", "log")
    ]
    assert leftovers == []
