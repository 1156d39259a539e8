"""The package builds with colcon (PyPI `colcon-common-extensions`) into the layout `ros2 run` uses.

colcon comes with the `test` extra: where it is missing, these tests fail (they do not skip).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from colcon_workspace import build_leftovers, colcon_build, colcon_test, site_packages

pytestmark = [pytest.mark.slow, pytest.mark.timeout(120)]

COLCON_TIMEOUT = 100  # one colcon build or test
PACKAGE = "fossbot_lidar_processing"


@pytest.fixture(scope="module")
def colcon_install(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`colcon build` of the package into a temporary workspace; returns its install prefix."""
    return colcon_build(PACKAGE, tmp_path_factory.mktemp("colcon"), timeout=COLCON_TIMEOUT)


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
    from ament_index_python.packages import get_package_prefix

    monkeypatch.setenv("AMENT_PREFIX_PATH", str(colcon_install))
    prefix = Path(get_package_prefix(PACKAGE))
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
    colcon_test(PACKAGE, colcon_install, timeout=COLCON_TIMEOUT)


def test_source_tree_stays_clean(colcon_install: Path) -> None:
    """Building leaves no egg-info or build output next to the sources (the harness ships them)."""
    assert build_leftovers(PACKAGE) == []
