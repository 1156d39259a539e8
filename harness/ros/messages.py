"""Scan <-> sensor_msgs/LaserScan, filled the fast way (FACTS.md: array.array)."""

from __future__ import annotations

import array

import numpy as np
from builtin_interfaces.msg import Time
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from harness.lidar.scan import Scan
from harness.ros.cdr import stamp_parts


def stamp(seconds: float) -> Time:
    """A builtin_interfaces/Time for a simulation time in seconds."""
    sec, nanosec = stamp_parts(seconds)
    return Time(sec=sec, nanosec=nanosec)


def clock_message(seconds: float) -> Clock:
    return Clock(clock=stamp(seconds))


def scan_message(scan: Scan) -> LaserScan:
    """The LaserScan the node under test receives: the exact float32 ranges."""
    msg = LaserScan()
    msg.header.stamp = stamp(scan.stamp)
    msg.header.frame_id = scan.frame_id
    msg.angle_min = float(scan.angle_min)
    msg.angle_max = float(scan.angle_max)
    msg.angle_increment = float(scan.angle_increment)
    msg.time_increment = float(scan.time_increment)
    msg.scan_time = float(scan.scan_time)
    msg.range_min = float(scan.range_min)
    msg.range_max = float(scan.range_max)
    msg.ranges = array.array("f", scan.ranges.astype(np.float32, copy=False).tobytes())
    msg.intensities = array.array("f", scan.intensities.astype(np.float32, copy=False).tobytes())
    return msg


def scan_from_message(msg: LaserScan) -> Scan:
    """The reverse, for recordings and for watching a board's own /scan."""
    return Scan(
        angle_min=msg.angle_min,
        angle_max=msg.angle_max,
        angle_increment=msg.angle_increment,
        time_increment=msg.time_increment,
        scan_time=msg.scan_time,
        range_min=msg.range_min,
        range_max=msg.range_max,
        ranges=np.frombuffer(msg.ranges, np.float32).copy(),
        intensities=np.frombuffer(msg.intensities, np.float32).copy(),
        stamp=msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9,
        frame_id=msg.header.frame_id,
    )
