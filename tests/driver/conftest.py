"""Fixtures for the LIDAR driver tests: the package on sys.path, ptys, driver processes, /scan.

The driver package lives in node/fossbot_lidar_driver (an ament_python
package, not part of the harness distribution), so its folder is put on
sys.path here and on PYTHONPATH for the driver processes. Nothing imports
rclpy at module level: the pure tests run without the ROS 2 wheels, and the
tests that need it carry the `ros` mark (tests/conftest.py stops a run that
selects them where rclpy is missing).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from harness.ros.domain import reserve_domain

pytest.register_assert_rewrite("child_process", "colcon_workspace", "driver_checks")

REPO = Path(__file__).resolve().parents[2]
PACKAGE_DIR = REPO / "node" / "fossbot_lidar_driver"
sys.path.insert(0, str(PACKAGE_DIR))

from child_process import ChildProcess, ChildProcesses  # noqa: E402
from driver_wire import Pty  # noqa: E402

MATCH_TIMEOUT = 15.0  # process start (~0.4 s) + discovery (~0.2 s), with room for a slow CI
SCAN_TIMEOUT = 10.0


@pytest.fixture
def pty() -> Iterator[Pty]:
    """A fresh pseudo-terminal, closed at teardown."""
    terminal = Pty.open()
    try:
        yield terminal
    finally:
        terminal.close()


@pytest.fixture
def ros_domain(monkeypatch: pytest.MonkeyPatch) -> Iterator[int]:
    """A domain id of this test's own, exported (localhost only) before any rclpy.init."""
    reservation = reserve_domain()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(reservation.domain_id))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    monkeypatch.delenv("ROS_LOCALHOST_ONLY", raising=False)
    monkeypatch.delenv("ROS_STATIC_PEERS", raising=False)
    try:
        yield reservation.domain_id
    finally:
        reservation.release()


@pytest.fixture
def start_driver(ros_domain: int, tmp_path: Path) -> Iterator[Callable[..., ChildProcess]]:
    """Start ``python -m fossbot_lidar_driver.<module> --ros-args ...`` on this test's domain."""
    children = ChildProcesses(tmp_path, role="driver")

    def start(
        module: str,
        *ros_args: str,
        command: list[str] | None = None,
        package_path: Path = PACKAGE_DIR,
        extra_env: dict[str, str] | None = None,
    ) -> ChildProcess:
        argv = command or [sys.executable, "-m", f"fossbot_lidar_driver.{module}"]
        if ros_args:
            argv = [*argv, "--ros-args", *ros_args]
        pythonpath = os.pathsep.join(
            p for p in (str(package_path), os.environ.get("PYTHONPATH")) if p
        )
        return children.start(argv, extra_env={"PYTHONPATH": pythonpath, **(extra_env or {})})

    with children:
        yield start


@dataclass
class ScanProbe:
    """The test side of the graph: a /scan subscription in a Context of its own."""

    node: Any
    executor: Any
    subscription: Any
    scans: list[Any] = field(default_factory=list)

    def wait_scans(self, count: int, process: ChildProcess, timeout: float = SCAN_TIMEOUT):
        """Spin until ``count`` scans arrived; fail (with the driver's log) after ``timeout``."""
        deadline = time.monotonic() + timeout
        while len(self.scans) < count:
            if time.monotonic() > deadline:
                pytest.fail(
                    f"{len(self.scans)} of {count} scans after {timeout} s; "
                    f"driver stderr:\n{process.stderr()}"
                )
            process.check_alive()
            self.executor.spin_once(timeout_sec=0.05)
        return self.scans[:count]


@pytest.fixture
def scan_probe(ros_domain: int) -> Iterator[Callable[..., ScanProbe]]:
    """A factory of /scan subscribers (reliable, keep-last 10) on this test's domain."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import LaserScan

    # A Context of our own keeps rclpy's signal handlers out of pytest.
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=ros_domain)
    executor = SingleThreadedExecutor(context=context)
    nodes: list[Any] = []

    def probe(topic: str = "/scan") -> ScanProbe:
        node = rclpy.create_node(f"driver_test_probe_{len(nodes)}", context=context)
        nodes.append(node)
        executor.add_node(node)
        result = ScanProbe(node, executor, None)
        result.subscription = node.create_subscription(LaserScan, topic, result.scans.append, 10)
        return result

    try:
        yield probe
    finally:
        for node in nodes:
            executor.remove_node(node)
            node.destroy_node()
        executor.shutdown(timeout_sec=1.0)
        rclpy.try_shutdown(context=context)
        context.destroy()
