#!/usr/bin/env python3
"""A Lab 07 node that makes one typical mistake, chosen by name (the audit's mutants).

Run as ``python3 mutant_node.py NAME --ros-args -p threshold:=0.4 ...``;
``correct`` is the control. Search this file for a name to find the lines
that make its mistake (harness/audit/mutants.py says what each does wrong);
every other line is the correct node: the nearest valid return (REP-117)
as a String and a Bool warning below ``threshold``, once per scan, the Bool
first. Only rclpy, the message packages, numpy and the standard library:
it runs as a student's node does, in a process of its own.
"""

import math
import sys
import time

import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, String

CONTROL = "correct"
MUTANT_NAMES = (
    # the angle of the nearest return
    "angle_in_degrees", "angle_without_angle_min", "angle_from_filtered_index",
    "angle_from_wrong_end",
    # which readings count
    "min_over_raw_ranges", "only_inf_filtered", "nan_not_filtered", "zero_as_obstacle",
    "below_range_min_kept", "above_range_max_kept", "front_sector_only",
    # the warning
    "threshold_hard_coded", "warning_inverted", "warning_latched", "warning_never",
    "rounded_before_comparing",
    # when and how it answers
    "one_scan_late", "silent_when_clear", "status_only_on_change", "status_twice",
    "crash_when_nothing_in_range", "slow_callback", "goes_silent",
    # units and configuration
    "centimetres", "scan_topic_ignored",
)  # fmt: skip
EXIT_UNKNOWN = 2

NO_OBSTACLE = "No obstacle detected"
LAB_THRESHOLD = 0.5  # the lab's example threshold (threshold_hard_coded)
FRONT_HALF_WIDTH = math.radians(30)  # front_sector_only
SLOW_CALLBACK_S = 1.5  # slow_callback
SILENT_AFTER = 10  # goes_silent: scans answered before it stops


class LidarNode(Node):
    """The Lab 07 node; `mistake` names the one thing it does wrong ("correct": nothing)."""

    def __init__(self, mistake):
        super().__init__("fossbot_lidar_node")
        self.mistake = mistake
        scan_topic = self.declare_parameter("lidar_topic", "/scan").value
        status_topic = self.declare_parameter("lidar_status_topic", "/lidar_status").value
        warning_topic = self.declare_parameter("warning_topic", "/obstacle_warning").value
        self.threshold = self.declare_parameter("threshold", LAB_THRESHOLD).value
        if self.mistake == "scan_topic_ignored":
            scan_topic = "/scan"  # the lab's default, whatever lidar_topic says
        if self.mistake == "threshold_hard_coded":
            self.threshold = LAB_THRESHOLD  # whatever the threshold parameter says
        self.warning_pub = self.create_publisher(Bool, warning_topic, 10)
        self.status_pub = self.create_publisher(String, status_topic, 10)
        self.scan_sub = self.create_subscription(LaserScan, scan_topic, self.on_scan, 10)
        self.scans = 0  # goes_silent
        self.warned = False  # warning_latched
        self.held_back = None  # one_scan_late: the previous scan's (warning, status)
        self.last_status = None  # status_only_on_change

    # -- one scan, start to end --------------------------------------------

    def on_scan(self, msg):
        self.scans += 1
        if self.mistake == "goes_silent" and self.scans > SILENT_AFTER:
            return  # nothing from its 11th scan on
        if self.mistake == "slow_callback":
            time.sleep(SLOW_CALLBACK_S)
        nearest = self.nearest(msg)
        if nearest is None:
            if self.mistake == "silent_when_clear":
                return  # nothing in range, so nothing said
            status, warning = NO_OBSTACLE, self.warning(math.inf)
        else:
            distance, index = nearest
            if self.mistake == "rounded_before_comparing":
                distance = round(distance, 1)  # and the warning compares this
            status = self.status(distance, self.angle(msg, index))
            warning = self.warning(distance)
        self.publish(warning, status)

    # -- which readings count, and the nearest of them ---------------------

    def valid(self, msg, ranges):
        """Which readings count (REP-117): finite, and range_min <= r <= range_max."""
        if self.mistake == "min_over_raw_ranges":
            return np.full(ranges.shape, True)  # every reading counts
        if self.mistake == "only_inf_filtered":
            return ranges != math.inf  # only the lab's +inf pitfall is dropped
        if self.mistake == "nan_not_filtered":  # NaN is neither inf nor out of limits
            return ~np.isinf(ranges) & ~(ranges < msg.range_min) & ~(ranges > msg.range_max)
        above_min = ranges >= msg.range_min
        if self.mistake == "zero_as_obstacle":
            above_min = np.full(ranges.shape, True)  # no range_min check
        if self.mistake == "below_range_min_kept":
            above_min = ranges > 0  # drops 0.0, not what is below range_min
        below_max = ranges <= msg.range_max
        if self.mistake == "above_range_max_kept":
            below_max = np.full(ranges.shape, True)  # no range_max check
        valid = np.isfinite(ranges) & above_min & below_max
        if self.mistake == "front_sector_only":
            angles = msg.angle_min + np.arange(ranges.size) * msg.angle_increment
            ahead = np.abs(np.arctan2(np.sin(angles), np.cos(angles))) <= FRONT_HALF_WIDTH
            valid &= ahead
        return valid

    def nearest(self, msg):
        """(distance, index in msg.ranges) of the nearest valid reading; None if none."""
        ranges = np.asarray(msg.ranges)
        candidates = np.flatnonzero(self.valid(msg, ranges))
        # crash_when_nothing_in_range forgets this check: argmin of nothing raises ValueError
        if candidates.size == 0 and self.mistake != "crash_when_nothing_in_range":
            return None
        position = int(np.argmin(ranges[candidates]))  # the first of equal minima
        index = int(candidates[position])
        distance = float(ranges[index])
        if self.mistake == "angle_from_filtered_index":
            index = position  # its index among the valid readings only
        return distance, index

    # -- what it says about it ---------------------------------------------

    def angle(self, msg, index):
        """The angle of beam `index`, in radians."""
        if self.mistake == "angle_without_angle_min":
            return index * msg.angle_increment
        if self.mistake == "angle_from_wrong_end":
            return msg.angle_max - index * msg.angle_increment
        return msg.angle_min + index * msg.angle_increment

    def status(self, distance, angle):
        """The status String for an obstacle `distance` metres away at `angle` radians."""
        if self.mistake == "angle_in_degrees":
            return f"Min distance: {distance:.3f} m, angle: {math.degrees(angle):.1f} deg"
        if self.mistake == "centimetres":
            return f"Min distance: {distance * 100:.1f} cm, angle: {angle:.3f} rad"
        if self.mistake == "rounded_before_comparing":  # printed as rounded (that is fine)
            return f"Min distance: {distance:.1f} m, angle: {angle:.3f} rad"
        return f"Min distance: {distance:.3f} m, angle: {angle:.3f} rad"

    def warning(self, distance):
        """True when the nearest valid return is closer than the threshold."""
        warning = distance < self.threshold
        if self.mistake == "warning_inverted":
            warning = not warning
        if self.mistake == "warning_latched":
            self.warned = self.warned or warning
            warning = self.warned
        return warning

    def publish(self, warning, status):
        """The Bool, then the String: one of each per scan."""
        if self.mistake == "one_scan_late":
            answer, self.held_back = self.held_back, (warning, status)
            if answer is None:
                return
            warning, status = answer
        if self.mistake != "warning_never":
            self.warning_pub.publish(Bool(data=warning))
        if self.mistake == "status_only_on_change" and status == self.last_status:
            return
        self.last_status = status
        self.status_pub.publish(String(data=status))
        if self.mistake == "status_twice":
            self.status_pub.publish(String(data=status))


def main():
    names = (CONTROL, *MUTANT_NAMES)
    mistake = sys.argv[1] if len(sys.argv) > 1 else ""
    if mistake not in names:
        print(
            f"mutant_node.py: unknown mutant {mistake!r}; known: {', '.join(names)}",
            file=sys.stderr,
        )
        return EXIT_UNKNOWN
    rclpy.init(args=sys.argv)
    node = LidarNode(mistake)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
