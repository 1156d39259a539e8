"""
Pure scan analysis for the Lab 07 LIDAR node: no rclpy, only numpy.

Kept apart from the node so the harness can import the reference logic, and
so the logic is unit-tested in milliseconds without a ROS graph.

Validity follows REP-117: a reading counts only if it is finite and
``range_min <= r <= range_max``. +inf (no return), -inf (too close) and NaN
(error) are invalid, and so are the 0.0 some drivers emit for "no return"
and any spurious value below ``range_min``.
"""

from __future__ import annotations

import array
from collections.abc import Sequence
from dataclasses import dataclass
from math import isfinite
from typing import Any

import numpy as np

__all__ = ['ObstacleReport', 'analyse_message', 'analyse_scan', 'check_threshold', 'status_text']

NO_OBSTACLE_TEXT = 'No obstacle detected'


@dataclass(frozen=True)
class ObstacleReport:
    """
    What one scan says about the nearest obstacle.

    ``distance``, ``angle`` and ``index`` are None exactly when
    ``obstacle`` is False; ``warning`` is then False too.
    """

    obstacle: bool
    distance: float | None
    angle: float | None
    index: int | None
    warning: bool


def _as_float_array(ranges: Sequence[float] | np.ndarray | array.array[float]) -> np.ndarray:
    """
    View ``ranges`` as a 1-D float numpy array, copying only when needed.

    ``LaserScan.ranges`` is an ``array.array('f')`` in rclpy: reading it with
    ``np.frombuffer`` is zero-copy, whereas iterating it costs microseconds
    per scan.
    """
    if isinstance(ranges, array.array) and ranges.typecode in ('f', 'd'):
        dtype = np.float32 if ranges.typecode == 'f' else np.float64
        values = np.frombuffer(ranges, dtype=dtype) if len(ranges) else np.zeros(0, dtype)
    elif isinstance(ranges, np.ndarray) and ranges.dtype.kind == 'f':
        values = ranges
    else:
        values = np.asarray(ranges, dtype=np.float64)
    if values.ndim != 1:
        raise ValueError(f'ranges must be one-dimensional, got shape {values.shape}')
    return values


def analyse_scan(
    ranges: Sequence[float] | np.ndarray | array.array[float],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    threshold: float,
) -> ObstacleReport:
    """
    Find the nearest valid reading of a scan, its angle and the warning.

    The angle is the lab's ``angle_min + index * angle_increment``, not
    wrapped into (-pi, pi]. Among equal minima the first index wins. The
    warning is strict: ``distance < threshold``. A scan with no valid
    reading (including an empty one) reports no obstacle.
    """
    values = _as_float_array(ranges)
    # Plain Python floats compare in the readings' own dtype (float32 for a
    # LaserScan, whose range fields are float32 too), so a reading equal to
    # range_max in the message is equal here.
    low, high = float(range_min), float(range_max)
    with np.errstate(invalid='ignore'):
        valid = np.isfinite(values) & (values >= low) & (values <= high)
    if not valid.any():
        return ObstacleReport(False, None, None, None, False)
    # Invalid entries become +inf so argmin sees only valid ones; argmin
    # returns the first of equal minima.
    index = int(np.argmin(np.where(valid, values, np.inf)))
    distance = float(values[index])
    angle = float(angle_min) + index * float(angle_increment)
    return ObstacleReport(True, distance, angle, index, distance < threshold)


def analyse_message(scan: Any, threshold: float) -> ObstacleReport:
    """
    Run ``analyse_scan`` on anything with LaserScan's field names.

    A sensor_msgs/LaserScan and the harness's own Scan both qualify.
    """
    return analyse_scan(
        scan.ranges,
        scan.angle_min,
        scan.angle_increment,
        scan.range_min,
        scan.range_max,
        threshold,
    )


def status_text(report: ObstacleReport) -> str:
    """
    Render a report as the lab's status String.

    The distance comes first and the angle second, so a reader that takes
    the first number as metres and the second as radians gets both.
    """
    if not report.obstacle:
        return NO_OBSTACLE_TEXT
    return f'Min distance: {report.distance:.3f} m, angle: {report.angle:.3f} rad'


def check_threshold(value: object) -> float:
    """
    Return ``value`` as a warning threshold in metres, or raise ValueError.

    A threshold must be a finite positive number: zero would never warn and
    a NaN would silently disable the warning.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f'threshold must be a number of metres, got {value!r}')
    threshold = float(value)
    if not isfinite(threshold) or threshold <= 0.0:
        raise ValueError(f'threshold must be finite and > 0 m, got {value!r}')
    return threshold
