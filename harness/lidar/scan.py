"""The emitted LIDAR scan: exactly the fields of sensor_msgs/LaserScan.

Everything downstream of the simulator (faults, links, oracle, recordings)
speaks this one type, so a scan judged by the oracle is byte for byte the
scan the node under test received.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Scan:
    """One revolution, with REP-117 semantics for the values in ``ranges``."""

    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float
    ranges: np.ndarray  # float32, one per beam
    intensities: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))
    stamp: float = 0.0  # simulation time of the first beam, seconds
    frame_id: str = "lidar_scan_frame"

    def __post_init__(self) -> None:
        object.__setattr__(self, "ranges", np.asarray(self.ranges, dtype=np.float32))
        object.__setattr__(self, "intensities", np.asarray(self.intensities, dtype=np.float32))

    def angles(self) -> np.ndarray:
        """Beam angles as the lab computes them: angle_min + i * angle_increment."""
        return self.angle_min + np.arange(self.ranges.size) * self.angle_increment

    def valid_mask(self) -> np.ndarray:
        """REP-117 validity: finite and within [range_min, range_max]."""
        r = self.ranges
        with np.errstate(invalid="ignore"):
            return np.isfinite(r) & (r >= self.range_min) & (r <= self.range_max)

    def to_bytes(self) -> bytes:
        """A canonical byte form, for determinism checks and digests."""
        head = np.array([*(getattr(self, name) for name in FLOATS), self.stamp], dtype=np.float64)
        return head.tobytes() + self.ranges.tobytes() + self.intensities.tobytes()


#: The layout's seven numbers, LaserScan's float fields in its order (angle_min ... range_max).
FLOATS = tuple(f.name for f in fields(Scan))[:7]


def scan_from_message(message: Any) -> Scan:
    """A sensor_msgs/LaserScan of any make (rclpy's as received, a recording's as rosbags
    reads it) as a Scan; its arrays are copied, so the message may be reused."""
    stamp = message.header.stamp
    return Scan(
        **{name: float(getattr(message, name)) for name in FLOATS},
        ranges=np.array(message.ranges, dtype=np.float32),
        intensities=np.array(message.intensities, dtype=np.float32),
        stamp=stamp.sec + stamp.nanosec * 1e-9,
        frame_id=message.header.frame_id,
    )
