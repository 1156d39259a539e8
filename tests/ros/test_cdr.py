"""The scan and clock bytes the harness publishes are the messages rclpy would send."""

from __future__ import annotations

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from harness.lidar.scan import Scan
from harness.ros.cdr import clock_cdr, scan_cdr
from harness.ros.messages import stamp


def clock_message(seconds: float) -> Clock:
    return Clock(clock=stamp(seconds))


def scan_message(scan: Scan) -> LaserScan:
    """The same scan as a LaserScan object, filled as an rclpy user fills one."""
    msg = LaserScan()
    msg.header.stamp = stamp(scan.stamp)
    msg.header.frame_id = scan.frame_id
    msg.angle_min, msg.angle_max = float(scan.angle_min), float(scan.angle_max)
    msg.angle_increment, msg.time_increment = float(scan.angle_increment), scan.time_increment
    msg.scan_time = float(scan.scan_time)
    msg.range_min, msg.range_max = float(scan.range_min), float(scan.range_max)
    msg.ranges = scan.ranges.tolist()
    msg.intensities = scan.intensities.tolist()
    return msg


def scan(frame_id: str, beams: int, intensities: int) -> Scan:
    rng = np.random.default_rng(beams + intensities + len(frame_id))
    ranges = rng.uniform(0.0, 12.0, beams).astype(np.float32)
    ranges[::7] = np.inf  # no return
    ranges[3::11] = np.nan
    return Scan(
        angle_min=-3.14159,
        angle_max=3.14159,
        angle_increment=0.0175,
        time_increment=1e-5,
        scan_time=0.1,
        range_min=0.12,
        range_max=float("inf"),
        ranges=ranges,
        intensities=np.full(intensities, 47.0, np.float32),
        stamp=12.3456789,
        frame_id=frame_id,
    )


@pytest.mark.parametrize("frame_id", ["", "l", "la", "lab", "laser", "lidar_scan_frame", "é"])
@pytest.mark.parametrize(("beams", "intensities"), [(360, 0), (450, 450), (0, 0)])
def test_scan_bytes_read_back_as_the_laser_scan(frame_id: str, beams: int, intensities: int):
    """Every field, each frame_id length (the padding after it) and NaN/inf ranges come
    back as rclpy's own serialization of the same LaserScan gives them (its padding
    bytes are left as they were in memory, so the bytes themselves may differ there)."""
    ours = scan_cdr(scan(frame_id, beams, intensities))
    theirs = serialize_message(scan_message(scan(frame_id, beams, intensities)))
    assert len(ours) == len(theirs)
    got, want = deserialize_message(ours, LaserScan), deserialize_message(theirs, LaserScan)
    assert np.array_equal(np.array(got.ranges), np.array(want.ranges), equal_nan=True)
    got.ranges, want.ranges = [], []  # NaN != NaN: compared above
    assert got == want


@pytest.mark.parametrize("seconds", [0.0, 1.5, 0.1 * 7, 12345.678901234])
def test_clock_bytes_are_rclpys(seconds: float) -> None:
    assert clock_cdr(seconds) == serialize_message(clock_message(seconds))
    assert deserialize_message(clock_cdr(seconds), Clock) == clock_message(seconds)
