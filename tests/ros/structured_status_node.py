#!/usr/bin/env python3
"""A right Lab 07 node whose status is a structure, as students print one.

Run as ``python3 structured_status_node.py FORMAT --ros-args ...``, FORMAT one of
``json`` (json.dumps of the raw minimum: ``Infinity`` and ``null`` when nothing
is in range), ``dict`` (str() of a dict: ``inf`` and ``None``) or ``yaml``
(key: value lines: ``.inf`` and ``null``).
"""

import json
import math
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, String


def status_text(form, distance, angle):
    found = angle is not None
    if form == "json":
        return json.dumps({"obstacle": found, "min_distance": distance, "angle": angle})
    if form == "dict":
        return str({"obstacle": found, "distance": distance, "angle": angle})
    if not found:
        return "obstacle: false\ndistance: .inf\nangle: null"
    return f"obstacle: true\ndistance: {distance:.3f} m\nangle: {angle:.3f} rad"


class LidarNode(Node):
    def __init__(self, form):
        super().__init__("fossbot_lidar_node")
        self.form = form
        scan_topic = self.declare_parameter("lidar_topic", "/scan").value
        status_topic = self.declare_parameter("lidar_status_topic", "/lidar_status").value
        warning_topic = self.declare_parameter("warning_topic", "/obstacle_warning").value
        self.threshold = self.declare_parameter("threshold", 0.5).value
        self.sub = self.create_subscription(LaserScan, scan_topic, self.on_scan, 10)
        self.status_pub = self.create_publisher(String, status_topic, 10)
        self.warning_pub = self.create_publisher(Bool, warning_topic, 10)

    def on_scan(self, msg):
        best, angle = math.inf, None
        for i, r in enumerate(msg.ranges):
            if math.isfinite(r) and msg.range_min <= r <= msg.range_max and r < best:
                best, angle = r, msg.angle_min + i * msg.angle_increment
        self.status_pub.publish(String(data=status_text(self.form, best, angle)))
        self.warning_pub.publish(Bool(data=best < self.threshold))


def main():
    form = sys.argv[1] if len(sys.argv) > 1 else "json"
    if form not in ("json", "dict", "yaml"):
        sys.exit(f"unknown format {form!r}: json, dict or yaml")
    rclpy.init(args=sys.argv)
    node = LidarNode(form)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
