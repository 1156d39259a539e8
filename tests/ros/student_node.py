#!/usr/bin/env python3
"""A Lab 07 node as students write it from the lab text, with their typical bugs.

Run as ``python3 student_node.py VARIANT --ros-args ...``. ``correct`` and
``correct_bool_when_close`` are right (``own_warning_parameter`` is right but names its
warning topic parameter ``obstacle_warning_topic``); every other variant has one bug the
harness's default suite must catch.
"""

import math
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, String

VARIANTS = {
    "correct",
    "correct_bool_when_close",
    "min_over_raw_ranges",
    "no_range_min_filter",
    "crash_when_nothing_in_range",
    "angle_without_angle_min",
    "angle_in_degrees",
    "no_bool",
    "inverted_bool",
    "threshold_hard_coded",
    "topic_parameter_ignored",
    "slow_callback",
    "answers_twice",
    "unparseable",
    "goes_silent",
    "first_answer_wrong",
    "status_on_change",
    "silent_when_clear",
    "own_warning_parameter",
}


class LidarNode(Node):
    def __init__(self, variant):
        super().__init__("fossbot_lidar_node")
        self.variant = variant
        self.declare_parameter("lidar_topic", "/scan")
        self.declare_parameter("lidar_status_topic", "/lidar_status")
        # The lab names no warning parameter: a student may choose another name.
        warning_param = "warning_topic"
        if variant == "own_warning_parameter":
            warning_param = "obstacle_warning_topic"
        self.declare_parameter(warning_param, "/obstacle_warning")
        self.declare_parameter("threshold", 0.5)
        # Seconds a scan's callback takes before it answers (a slow but right node): every
        # scan's, or with slow_scan N only the N-th scan's (1 = the first it receives), and
        # with slow_count C the C scans from the N-th on.
        self.delay_s = self.declare_parameter("delay_s", 0.0).value
        self.slow_scan = self.declare_parameter("slow_scan", 0).value
        self.slow_count = self.declare_parameter("slow_count", 1).value
        scan_topic = self.get_parameter("lidar_topic").value
        if variant == "topic_parameter_ignored":
            scan_topic = "/scan"
        status_topic = self.get_parameter("lidar_status_topic").value
        self.threshold = self.get_parameter("threshold").value
        if variant == "threshold_hard_coded":
            self.threshold = 0.5
        self.sub = self.create_subscription(LaserScan, scan_topic, self.on_scan, 10)
        self.status_pub = self.create_publisher(String, status_topic, 10)
        self.warning_pub = self.create_publisher(Bool, self.get_parameter(warning_param).value, 10)

    def nearest(self, msg):
        best, best_i = math.inf, None
        for i, r in enumerate(msg.ranges):
            if self.variant != "min_over_raw_ranges":
                if not math.isfinite(r) or r > msg.range_max:
                    continue
                if r < msg.range_min and self.variant != "no_range_min_filter":
                    continue
            if r < best:
                best, best_i = r, i
        return best, best_i

    def on_scan(self, msg):
        self.scans = getattr(self, "scans", 0) + 1
        if self.variant == "goes_silent" and self.scans > 10:
            return
        if self.variant == "slow_callback":
            time.sleep(1.5)
        if self.slow_scan == 0 or 0 <= self.scans - self.slow_scan < self.slow_count:
            time.sleep(self.delay_s)
        if self.variant == "crash_when_nothing_in_range":
            valid = [r for r in msg.ranges if msg.range_min <= r <= msg.range_max]
            best = min(valid)  # ValueError when nothing is in range
            index = list(msg.ranges).index(best)
        else:
            best, index = self.nearest(msg)
        status = String()
        if index is None:
            status.data = "No obstacle"
            warning = False
        else:
            if self.variant == "angle_without_angle_min":
                angle = index * msg.angle_increment
            else:
                angle = msg.angle_min + index * msg.angle_increment
            if self.variant == "angle_in_degrees":
                angle = math.degrees(angle)
            if self.variant == "correct":
                status.data = f"Obstacle at {best:.2f} m, {angle:.2f} rad"
            else:
                status.data = f"Min distance: {best:.3f} m, angle: {angle:.3f} rad"
            warning = best < self.threshold
        if self.variant == "unparseable":
            status.data = "obstacle: yes-ish"
        if self.variant == "first_answer_wrong" and self.scans == 1:
            status.data = "Min distance: 0.000 m, angle: 0.000 rad"  # a value not yet computed
        if self.variant == "silent_when_clear" and index is None:
            return
        if self.variant == "status_on_change":
            if status.data == getattr(self, "last_status", None):
                self.warning_pub.publish(Bool(data=warning))
                return
            self.last_status = status.data
        self.status_pub.publish(status)
        if self.variant == "answers_twice":
            self.status_pub.publish(status)
        if self.variant == "inverted_bool":
            warning = not warning
        if self.variant == "no_bool":
            return
        if self.variant == "correct_bool_when_close" and not warning:
            return
        self.warning_pub.publish(Bool(data=warning))


def main():
    variant = sys.argv[1] if len(sys.argv) > 1 else "correct"
    if variant not in VARIANTS:
        sys.exit(f"unknown variant {variant!r}")
    rclpy.init(args=sys.argv)
    node = LidarNode(variant)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
