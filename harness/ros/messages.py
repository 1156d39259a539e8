"""A stamp as a ROS Time; a LaserScan received is read by `harness.lidar.scan.scan_from_message`.

The harness publishes its own scans and clocks as bytes (``harness.ros.cdr``).
"""

from __future__ import annotations

from builtin_interfaces.msg import Time

from harness.ros.cdr import stamp_parts


def stamp(seconds: float) -> Time:
    """A builtin_interfaces/Time for a simulation time in seconds."""
    sec, nanosec = stamp_parts(seconds)
    return Time(sec=sec, nanosec=nanosec)
