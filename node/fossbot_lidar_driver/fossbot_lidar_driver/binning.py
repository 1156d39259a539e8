"""
Device angles to LaserScan bins: the pure part of both drivers (numpy only).

Both LIDARs report angles in degrees increasing CLOCKWISE seen from above;
REP-103 angles increase counter-clockwise. A reading at device angle ``theta``
lands in bin ``k`` of a scan with ``bins`` bins over [0, 2*pi) (angle_min 0,
angle_increment 2*pi/bins) by

    a = (-theta if invert else theta) + angle_offset_deg        (degrees)
    nearest: k = floor(((a mod 360) * bins / 360) + 0.5) mod bins
    floor:   k = int(((radians(a)) mod 2*pi) / (2*pi / bins))   (dropped if k == bins)

A device whose zero points ``yaw`` degrees counter-clockwise from the robot's
forward and counts clockwise (seen from above) is shown in the robot's frame
by ``invert`` true and ``angle_offset_deg = yaw``; mounted upside down, it
counts counter-clockwise: ``invert`` false. The FOSSBot v2's A1 points its
zero to the right (yaw -90), the nodes' default; these functions default to a
device whose zero points forward (offset 0).

``nearest`` (the default) centres bin ``k`` on its labelled angle
``k * angle_increment``, so a sample sent at exactly that angle (as an
emulator naturally does) always lands in bin ``k``. It works in degrees,
where device angles (multiples of 1/64 degree) are exact. ``floor`` is the
lab robot's bridge (LRMPUT/fossbot-ros2-bridge, fossbot_bridge/lidar_node.py)
operation for operation: bin ``k`` then covers [k, k+1) increments.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    'BIN_MODES',
    'bin_indices',
    'ld_ranges',
    'nearest_per_bin',
    'rplidar_ranges',
    'scan_angle_max',
    'scan_increment',
]

BIN_MODES = ('nearest', 'floor')


def scan_increment(bins: int) -> float:
    """Return the angle between two bins in radians (2*pi / bins)."""
    return 2.0 * math.pi / bins


def scan_angle_max(bins: int) -> float:
    """Return the last bin's angle: 2*pi minus one increment, as the bridge publishes it."""
    return 2.0 * math.pi - scan_increment(bins)


def bin_indices(
    angles_deg: np.ndarray,
    bins: int,
    *,
    invert: bool = True,
    angle_offset_deg: float = 0.0,
    mode: str = 'nearest',
) -> np.ndarray:
    """
    Return the bin of each device angle (int64; ``bins`` marks "no bin").

    Only ``floor`` can yield ``bins``: where float rounding takes an angle a
    hair below 2*pi up to 2*pi, the bridge drops the reading, and so do we.
    """
    theta = np.asarray(angles_deg, dtype=np.float64)
    if mode == 'nearest':
        ccw = (-theta if invert else theta) + angle_offset_deg
        index = np.floor(np.mod(ccw, 360.0) * bins / 360.0 + 0.5).astype(np.int64)
        return np.mod(index, bins)
    if mode == 'floor':
        # The bridge's arithmetic, in its order: radians, negate, add offset,
        # Python-style modulo (np.mod matches `%` on floats), divide, truncate.
        a = np.radians(theta)
        if invert:
            a = -a
        a = a + math.radians(angle_offset_deg)
        index = (np.mod(a, 2.0 * math.pi) / scan_increment(bins)).astype(np.int64)
        return np.where((index >= 0) & (index < bins), index, bins)
    raise ValueError(f'bin mode must be one of {BIN_MODES}, got {mode!r}')


def nearest_per_bin(
    index: np.ndarray, ranges_m: np.ndarray, bins: int, empty: float
) -> np.ndarray:
    """
    Return ``bins`` ranges: the smallest reading that fell in each bin, else ``empty``.

    NaN readings never beat a number (``fmin``), so a bin is NaN only when
    nothing but NaNs fell in it: the LD vendor driver's rule. ``index ==
    bins`` means "no bin" and is skipped.
    """
    out = np.full(bins + 1, empty, dtype=np.float64)
    np.fmin.at(out, np.asarray(index, dtype=np.int64), np.asarray(ranges_m, dtype=np.float64))
    return out[:bins]


def rplidar_ranges(
    angles_deg: np.ndarray,
    distances_mm: np.ndarray,
    bins: int,
    *,
    range_min: float,
    range_max: float,
    invert: bool = True,
    angle_offset_deg: float = 0.0,
    mode: str = 'nearest',
) -> np.ndarray:
    """
    Rasterise one RPLIDAR revolution as the lab robot does; empty bins are +inf.

    The lab chain: its agent keeps samples with distance > 0 and sends angle
    and distance rounded to 0.01 degree and 0.1 mm (JSON); the bridge drops
    readings outside [range_min, range_max] (bounds kept) and keeps the
    nearest reading of each bin. Quality is not looked at (rplidar-roboticia's
    iter_scans keeps quality-0 samples with a distance).
    """
    angles = np.asarray(angles_deg, dtype=np.float64)
    distances = np.asarray(distances_mm, dtype=np.float64)
    returned = distances > 0.0
    # For the RPLIDAR's 1/64-degree angles and 1/4-mm distances numpy's
    # rounding gives what Python's round() gives: both are exact ties, half-even.
    angles = np.round(angles[returned], 2)
    metres = np.round(distances[returned], 1) / 1000.0
    usable = (metres >= range_min) & (metres <= range_max)
    index = bin_indices(
        angles[usable], bins, invert=invert, angle_offset_deg=angle_offset_deg, mode=mode
    )
    return nearest_per_bin(index, metres[usable], bins, math.inf)


def ld_ranges(
    angles_deg: np.ndarray,
    distances_mm: np.ndarray,
    intensities: np.ndarray,
    bins: int,
    *,
    invert: bool = True,
    angle_offset_deg: float = 0.0,
    mode: str = 'nearest',
) -> np.ndarray:
    """
    Rasterise one LD06/LD19 revolution as the vendor ROS 2 driver does; empty bins are NaN.

    ldlidar_stl_ros2 turns a point with distance 0 AND intensity 0 into NaN,
    keeps every other reading as sent (0 with an intensity stays 0.0; nothing
    is dropped for range_min/range_max, which only go in the header), and
    keeps the nearest number in each bin.
    """
    distances = np.asarray(distances_mm, dtype=np.float64)
    intensity = np.asarray(intensities)
    metres = distances / 1000.0
    metres[(distances == 0.0) & (intensity == 0)] = math.nan
    index = bin_indices(
        angles_deg, bins, invert=invert, angle_offset_deg=angle_offset_deg, mode=mode
    )
    return nearest_per_bin(index, metres, bins, math.nan)
