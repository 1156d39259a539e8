"""The FOSSBot v2 bridge's LIDAR node, as the lab's PC runs it, for tests.

On the PC (LRMPUT/fossbot-ros2-bridge, fossbot_bridge/lidar_node.py) a node
named ``fossbot_lidar`` connects to the robot agent's LIDAR port, reads one
JSON revolution a line and bins it: ``angle_bins`` bins over [0, 2*pi), a
reading at device angle theta lands in bin ``int(((-theta if invert else
theta) + angle_offset_deg) mod 360 / step)`` (radians in the real one), empty
bins +inf, readings outside [range_min, range_max] dropped, the nearest kept;
published on /scan, reliable, keep-last 5, stamped with the PC's clock,
scan_time the smoothed interval between revolutions. The robot's
config/bridge.yaml sets ``invert: true`` and ``angle_offset_deg: -90``; the
node's own defaults are ``false`` and ``0``. It reconnects every
``reconnect_period`` s when the agent is not there (yet). Only the agent's
address (``robot_host``, ``lidar_port``) is a parameter here that the real
one takes from its protocol module.
"""

from __future__ import annotations

import json
import math
import socket
import threading
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan

SCAN_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST, depth=5
)


class LidarBridge(Node):
    def __init__(self) -> None:
        super().__init__("fossbot_lidar")
        for name, default in (
            ("robot_host", "127.0.0.1"),
            ("lidar_port", 5008),
            ("frame_id", "lidar_scan_frame"),
            ("angle_bins", 360),
            ("range_min", 0.15),
            ("range_max", 12.0),
            ("angle_offset_deg", 0.0),
            ("invert", False),
            ("reconnect_period", 3.0),
            ("read_timeout", 30.0),
        ):
            self.declare_parameter(name, default)
        value = lambda name: self.get_parameter(name).value  # noqa: E731
        self.address = (value("robot_host"), int(value("lidar_port")))
        self.frame_id = value("frame_id")
        self.bins = int(value("angle_bins"))
        self.range_min, self.range_max = value("range_min"), value("range_max")
        self.offset = math.radians(value("angle_offset_deg"))
        self.invert = bool(value("invert"))
        self.reconnect_period = value("reconnect_period")
        self.read_timeout = value("read_timeout")
        self.publisher = self.create_publisher(LaserScan, "/scan", SCAN_QOS)
        self.running = True
        self.last_scan_at: float | None = None
        self.period: float | None = None
        threading.Thread(target=self.stream, daemon=True).start()

    def stream(self) -> None:
        while self.running:
            try:
                sock = socket.create_connection(self.address, timeout=10.0)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                sock.settimeout(self.read_timeout)
                self.get_logger().info("lidar connected")
                for line in sock.makefile("r"):
                    if not self.running:
                        break
                    try:
                        payload = json.loads(line)
                    except ValueError:
                        continue
                    self.publish(payload)
                sock.close()
            except Exception as err:  # noqa: BLE001 - as the bridge: log, retry
                self.get_logger().warn(f"lidar link: {err}")
            if self.running:
                time.sleep(self.reconnect_period)

    def publish(self, payload: dict) -> None:
        points = payload.get("pts", [])
        if not points:
            return
        step = 2.0 * math.pi / self.bins
        ranges = [math.inf] * self.bins
        for angle_deg, distance_mm in points:
            if distance_mm <= 0:
                continue
            distance = distance_mm / 1000.0
            if distance < self.range_min or distance > self.range_max:
                continue
            angle = math.radians(angle_deg)
            angle = (-angle if self.invert else angle) + self.offset
            index = int((angle % (2.0 * math.pi)) / step)
            if 0 <= index < self.bins and distance < ranges[index]:
                ranges[index] = distance
        scan = LaserScan()
        scan.header.stamp = self.get_clock().now().to_msg()
        scan.header.frame_id = self.frame_id
        scan.angle_min, scan.angle_max, scan.angle_increment = 0.0, 2.0 * math.pi - step, step
        scan.range_min, scan.range_max = float(self.range_min), float(self.range_max)
        now = time.monotonic()
        if self.last_scan_at is not None and 0.05 < now - self.last_scan_at < 2.0:
            gap = now - self.last_scan_at
            self.period = 0.9 * self.period + 0.1 * gap if self.period else gap
        self.last_scan_at = now
        scan.scan_time = float(self.period or 0.15)
        scan.time_increment = scan.scan_time / self.bins
        scan.ranges = ranges
        self.publisher.publish(scan)


def main() -> None:
    rclpy.init()
    node = LidarBridge()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.running = False
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
