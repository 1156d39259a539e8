"""The driver package builds with colcon into the layout `ros2 run` uses, and its tests pass.

colcon comes with the `test` extra: where it is missing, these tests fail (they do not skip).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from colcon_workspace import build_leftovers, colcon_build, colcon_test, site_packages
from driver_wire import BURST_PERIOD, LdStreamer, burst

pytestmark = [pytest.mark.slow, pytest.mark.timeout(180)]

COLCON_TIMEOUT = 150  # one colcon build or test
PACKAGE = "fossbot_lidar_driver"
EXECUTABLES = ("rplidar_node", "ldlidar_node")


@pytest.fixture(scope="module")
def colcon_install(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`colcon build` of the package into a temporary workspace; returns its install prefix."""
    return colcon_build(PACKAGE, tmp_path_factory.mktemp("colcon"), timeout=COLCON_TIMEOUT)


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
    colcon_test(PACKAGE, colcon_install, timeout=COLCON_TIMEOUT)


def test_source_tree_stays_clean(colcon_install: Path) -> None:
    """Building leaves no egg-info or build output next to the sources."""
    assert build_leftovers(PACKAGE) == []
