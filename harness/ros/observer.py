"""The harness's own ROS 2 node: publishes /scan and /clock, hears the answers.

It lives in its own rclpy Context (domain id given explicitly), is spun by
hand with bounded ``spin_once`` calls (no threads), and stamps everything it
hears with the publisher's DDS source timestamp, so answers can be matched
to the scan they belong to.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, String

from harness.ros.messages import clock_message, scan_from_message, scan_message
from harness.scan import Scan

QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE)


@dataclass(frozen=True)
class Heard:
    """One message from the node under test."""

    kind: str  # "status", "warning", or "scan" (a driver's scan, when watching)
    value: str | bool | Scan
    source_ns: int  # when the node published it (DDS source timestamp, system clock)
    arrived: float  # time.perf_counter() when the harness took it


def discovery_environment(*, network: bool) -> dict[str, str]:
    """Environment that keeps discovery on this machine unless a network is wanted."""
    return {} if network else {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


class Observer:
    """Publish scans and collect the node's String and Bool answers."""

    def __init__(
        self,
        domain_id: int,
        *,
        scan_topic: str,
        status_topic: str,
        warning_topic: str,
        network: bool = False,
        publish_scans: bool = True,
    ) -> None:
        # rmw reads the discovery range from the environment at init.
        os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
        os.environ.update(discovery_environment(network=network))
        self.context = Context()
        # The harness handles SIGINT/SIGTERM itself (stop the node, report);
        # rclpy's own handlers would shut the context down under our feet.
        rclpy.init(
            context=self.context,
            domain_id=domain_id,
            signal_handler_options=SignalHandlerOptions.NO,
        )
        self.node = rclpy.create_node("fossbot_hil", context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.scan_topic, self.status_topic = scan_topic, status_topic
        # Either we publish the scans (ros2 link) or a board's driver does and
        # we listen to what the node under test receives (serial links).
        self.scan_pub = (
            self.node.create_publisher(LaserScan, scan_topic, QOS) if publish_scans else None
        )
        self.scan_sub = (
            None
            if publish_scans
            else self.node.create_subscription(
                LaserScan, scan_topic, self._hear("scan", scan_from_message), QOS
            )
        )
        self.clock_pub = self.node.create_publisher(Clock, "/clock", QOS)
        self.inbox: list[Heard] = []
        self.status_sub = self.node.create_subscription(
            String, status_topic, self._hear("status", lambda m: m.data), QOS
        )
        self.warning_sub = self.node.create_subscription(
            Bool, warning_topic, self._hear("warning", lambda m: bool(m.data)), QOS
        )

    def publish_clock(self, seconds: float) -> None:
        self.clock_pub.publish(clock_message(seconds))

    def _hear(self, kind: str, value_of: Callable[[Any], str | bool | Scan]):
        def callback(msg: object, info: dict) -> None:
            self.inbox.append(
                Heard(kind, value_of(msg), int(info["source_timestamp"]), time.perf_counter())
            )

        return callback

    def publish(self, scan: Scan) -> int:
        """Publish /clock then the scan; return the send time in system-clock ns."""
        assert self.scan_pub is not None, "this observer watches a driver's scans"
        msg = scan_message(scan)
        self.clock_pub.publish(clock_message(scan.stamp))
        sent = time.time_ns()
        self.scan_pub.publish(msg)
        return sent

    def spin(self, timeout: float) -> None:
        """Handle what arrived, waiting at most `timeout` seconds for something."""
        self.executor.spin_once(timeout_sec=max(0.0, timeout))

    def drain(self, limit: int = 100) -> None:
        """Handle everything already queued without waiting."""
        for _ in range(limit):
            before = len(self.inbox)
            self.executor.spin_once(timeout_sec=0.0)
            if len(self.inbox) == before:
                return

    def warning_publishers(self) -> int:
        """Publishers of the node's warning topic matched to our subscription."""
        return self.warning_sub.get_publisher_count()

    def ready(self) -> bool:
        """The node reads our scans and publishes its status (matched, not just announced)."""
        if self.scan_pub is not None:
            reads_scans = self.scan_pub.get_subscription_count() > 0
        else:  # the driver publishes scans and someone besides us reads them
            assert self.scan_sub is not None
            reads_scans = (
                self.scan_sub.get_publisher_count() > 0
                and self.node.count_subscribers(self.scan_topic) > 1
            )
        return reads_scans and self.status_sub.get_publisher_count() > 0

    def _scan_readers(self) -> int:
        """Readers of the scan topic other than this observer."""
        if self.scan_pub is not None:
            return self.scan_pub.get_subscription_count()
        return self.node.count_subscribers(self.scan_topic) - 1

    def graph_summary(self) -> str:
        """What the node under test offers, for 'never became ready' explanations."""
        topics = [
            f"{name} [{', '.join(t.split('/')[-1] for t in types)}]"
            for name, types in self.node.get_topic_names_and_types()
            if name not in ("/rosout", "/parameter_events", "/clock")
        ]
        return (
            f"subscribers on {self.scan_topic}: {self._scan_readers()}, "
            f"publishers on {self.status_topic}: {self.status_sub.get_publisher_count()}; "
            f"topics seen: {', '.join(topics) or 'none'}"
        )

    def close(self) -> None:
        """Tear down node, executor and context, in that order; safe to call twice.

        The context must be destroyed too: until then its DDS participant
        lives on and a later run in the same domain can still see it.
        """
        if self.context.ok():
            self.node.destroy_node()
            self.executor.shutdown(timeout_sec=1.0)
            self.context.try_shutdown()
            self.context.destroy()
