"""Turning an emitted Scan into the measurements a spinning LIDAR would send.

The devices count degrees clockwise from their own zero, a ``Scan``
radians counter-clockwise from ahead (REP-103), and the mount says where the
zero points (``harness.lidar.mount``). This is the one place that converts,
so the codecs only see device samples (docs/devices.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from harness.lidar.mount import FORWARD, LidarMount
from harness.lidar.scan import Scan

# The quality the vendor SDK gives every express-scan sample (0x2F): a
# plausible mid-range RPLIDAR quality for returns. LD devices want a higher
# intensity (their ROS driver filters weak near returns): pass one.
DEFAULT_QUALITY = 47


@dataclass(frozen=True)
class Sample:
    """One device measurement, in the device's own convention."""

    angle_deg: float  # clockwise from the device's zero, [0, 360)
    distance_mm: float  # 0.0 = no return (also "too close": devices send 0 for both)
    quality: int  # RPLIDAR: 0..63 (0 when distance is 0); LD: intensity 0..255


def device_angle_deg(
    ccw_rad: float | np.ndarray, mount: LidarMount = FORWARD
) -> float | np.ndarray:
    """A REP-103 angle (CCW, radians) as a device angle (degrees, [0, 360)) on `mount`.

    Clockwise from the device's zero at ``mount.yaw_deg``; counter-clockwise
    when the device is mirrored (upside down). The generic mount: ``-degrees mod 360``.
    """
    deg = np.degrees(np.asarray(ccw_rad, dtype=np.float64))
    turn = deg - mount.yaw_deg if mount.mirrored else mount.yaw_deg - deg
    deg = np.mod(turn, 360.0)
    # A tiny negative angle rounds to 360.0, and -0.0 prints oddly: both are 0.
    deg = np.where(deg >= 360.0, 0.0, deg) + 0.0
    return float(deg) if deg.ndim == 0 else deg


def encode_distances_mm(ranges_m: np.ndarray, max_range_m: float | None = None) -> np.ndarray:
    """Metres (REP-117) to device millimetres; 0 for "nothing usable" or beyond ``max_range_m``.

    A finite reading below range_min is kept: the device would report it, and
    filtering it is the driver's job.
    """
    r = np.asarray(ranges_m, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        usable = np.isfinite(r) & (r > 0.0)
        if max_range_m is not None:
            usable &= r <= max_range_m
    return np.where(usable, r * 1000.0, 0.0)


def samples_from_scan(
    scan: Scan,
    *,
    samples_per_rev: int | None = None,
    max_range_m: float | None = None,
    quality: int = DEFAULT_QUALITY,
    mount: LidarMount = FORWARD,
) -> list[Sample]:
    """The samples of one revolution, in increasing device angle from about 0.

    Without ``samples_per_rev``, one sample per beam; with it, sample ``j``
    looks at device angle ``j * 360 / samples_per_rev`` (plus ``_grid_phase``)
    and takes the nearest beam, or no return where none is within half an
    increment.
    """
    distances = encode_distances_mm(scan.ranges, max_range_m)
    if samples_per_rev is None:
        angles = np.asarray(device_angle_deg(scan.angles(), mount), dtype=np.float64)
    else:
        if samples_per_rev < 1:
            raise ValueError(f"samples_per_rev must be positive, got {samples_per_rev}")
        step = 360.0 / samples_per_rev
        angles = np.arange(samples_per_rev, dtype=np.float64) * step
        phase = _grid_phase(mount, step)
        if phase:
            angles = angles + phase
        distances = _nearest_beam(scan, angles, distances, mount)
    return _samples(angles, distances, quality)


def samples_at_beams(
    scan: Scan,
    *,
    max_count: int | None = None,
    max_range_m: float | None = None,
    quality: int = DEFAULT_QUALITY,
    mount: LidarMount = FORWARD,
) -> list[Sample]:
    """One sample per beam, at the angle the simulator cast it, in increasing device angle.

    A device that reports each sample's angle (RPLIDAR standard nodes) need
    not resample; ``max_count`` keeps that many beams, spread evenly.
    """
    n = scan.ranges.size
    index = np.arange(n)
    if max_count is not None:
        if max_count < 1:
            raise ValueError(f"max_count must be positive, got {max_count}")
        if n > max_count:
            index = np.unique(np.floor(np.arange(max_count) * (n / max_count)).astype(np.int64))
    angles = np.asarray(device_angle_deg(scan.angles(), mount), dtype=np.float64)
    angles = angles.reshape(-1)[index]
    distances = encode_distances_mm(scan.ranges, max_range_m)[index]
    return _samples(angles, distances, quality)


def _samples(angles: np.ndarray, distances: np.ndarray, quality: int) -> list[Sample]:
    """The samples in increasing device angle; no quality where there is no return."""
    qualities = np.where(distances > 0.0, int(quality), 0)
    order = np.argsort(angles, kind="stable").tolist()
    return [Sample(float(angles[i]), float(distances[i]), int(qualities[i])) for i in order]


def _grid_phase(mount: LidarMount, step: float) -> float:
    """Where the resampled device angles start, in [0, step): 0 on the generic mount.

    The samples fall on the same robot-frame angles whatever the mount, so a
    yaw that is no whole number of steps (the v2's -90 deg of an LD19's 0.8)
    does not put every sample half-way between a driver's bins.
    """
    turn = -mount.yaw_deg if mount.mirrored else mount.yaw_deg
    phase = float(np.mod(turn, step))
    return 0.0 if phase < 1e-9 or phase > step - 1e-9 else phase


def _nearest_beam(
    scan: Scan, device_deg: np.ndarray, distances: np.ndarray, mount: LidarMount = FORWARD
) -> np.ndarray:
    """Distances seen at the given device angles on `mount`: nearest beam, 0 if none is near."""
    n = scan.ranges.size
    if n == 0:
        return np.zeros(device_deg.size)
    # device_angle_deg's inverse (mod 360): where in the scan frame each device angle looks.
    scan_deg = device_deg + mount.yaw_deg if mount.mirrored else mount.yaw_deg - device_deg
    ccw = np.radians(scan_deg)
    inc = scan.angle_increment if n > 1 else 2 * math.pi
    rel = np.mod(ccw - scan.angle_min, 2 * math.pi)  # [0, 2*pi) past the first beam
    index = np.rint(rel / inc).astype(np.int64)
    gap = np.abs(rel - index * inc)
    beyond = index > n - 1
    # Past the last beam: the nearer of the last beam and (wrapping) the first.
    to_last = rel - (n - 1) * inc
    to_first = 2 * math.pi - rel
    use_first = beyond & (to_first <= to_last)
    index = np.where(beyond, np.where(use_first, 0, n - 1), index)
    gap = np.where(beyond, np.minimum(to_first, to_last), gap)
    covered = gap <= inc / 2 + 1e-9
    return np.where(covered, distances[index], 0.0)
