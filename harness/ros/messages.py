"""sensor_msgs/LaserScan -> Scan (what a board's driver publishes), and a stamp as a ROS Time.

The harness publishes its own scans and clocks as bytes (``harness.ros.cdr``).
"""

from __future__ import annotations

import numpy as np
from builtin_interfaces.msg import Time
from sensor_msgs.msg import LaserScan

from harness.lidar.scan import Scan
from harness.ros.cdr import stamp_parts


def stamp(seconds: float) -> Time:
    """A builtin_interfaces/Time for a simulation time in seconds."""
    sec, nanosec = stamp_parts(seconds)
    return Time(sec=sec, nanosec=nanosec)


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
