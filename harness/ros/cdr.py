"""The scan and the clock as the CDR bytes rmw publishes (pure: no rclpy).

Publishing bytes (rclpy's raw publish) skips the field-by-field copy into the C struct
and its serialisation: about half the cost of a send. XCDR1 little-endian, as
rmw_fastrtps writes it; `tests/ros` checks the bytes against rclpy's."""

from __future__ import annotations

import struct

import numpy as np

from harness.lidar.scan import FLOATS, Scan

__all__ = ["clock_cdr", "scan_cdr", "stamp_parts"]

ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR, little-endian
FLOAT32 = np.dtype("<f4")


def stamp_parts(seconds: float) -> tuple[int, int]:
    """builtin_interfaces/Time (sec, nanosec) for a simulation time in seconds."""
    nanoseconds = round(seconds * 1e9)
    return nanoseconds // 1_000_000_000, nanoseconds % 1_000_000_000


def clock_cdr(seconds: float) -> bytes:
    """rosgraph_msgs/Clock at `seconds`."""
    return ENCAPSULATION + struct.pack("<iI", *stamp_parts(seconds))


def scan_cdr(scan: Scan) -> bytes:
    """sensor_msgs/LaserScan with the scan's fields, ranges and intensities as float32."""
    frame_id = scan.frame_id.encode() + b"\0"
    header = struct.pack("<iII", *stamp_parts(scan.stamp), len(frame_id)) + frame_id
    header += b"\0" * (-len(header) % 4)  # the float32 fields align to 4
    fields = np.array([getattr(scan, name) for name in FLOATS], FLOAT32)  # angle_min ...
    sequences = (_floats(scan.ranges), _floats(scan.intensities))
    return b"".join((ENCAPSULATION, header, fields.tobytes(), *sequences))


def _floats(values: np.ndarray) -> bytes:
    """A CDR sequence<float32>: its length, then its items."""
    values = np.asarray(values, FLOAT32)
    return struct.pack("<I", values.size) + values.tobytes()
