"""Processing functions as students write them from the lab text, right and wrong.

Each is ``fn(scan, threshold) -> (status, warning)`` for the inprocess link;
the tests check that the shipped scenarios pass the right ones and catch
every bug below.
"""

from __future__ import annotations

import math

import numpy as np


def _valid_min(scan, *, use_range_min=True, use_finite=True):
    best, index = math.inf, None
    for i, r in enumerate(scan.ranges.tolist()):
        if use_finite and not math.isfinite(r):
            continue
        if use_range_min and r < scan.range_min:
            continue
        if r > scan.range_max:
            continue
        if r < best:
            best, index = r, i
    return best, index


def correct_other_wording(scan, threshold):
    """Right, worded differently, and printing degrees as well as radians."""
    d, i = _valid_min(scan)
    if i is None:
        return "Path is clear", False
    a = scan.angle_min + i * scan.angle_increment
    return f"Obstacle! dist={d:.2f}m angle={a:.3f}rad ({math.degrees(a):.0f} deg)", d < threshold


def correct_bool_only_when_close(scan, threshold):
    """Right; publishes the warning only when it is True (allowed)."""
    d, i = _valid_min(scan)
    if i is None:
        return "no obstacle", None
    a = scan.angle_min + i * scan.angle_increment
    return f"{d:.3f} {a:.3f}", (True if d < threshold else None)


def min_over_raw_ranges(scan, threshold):
    """The lab's pitfall: min(msg.ranges) with no filtering at all."""
    d = float(min(scan.ranges.tolist()))
    i = int(np.argmin(scan.ranges))
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < threshold


def no_range_min_filter(scan, threshold):
    """Filters non-finite values but keeps returns below range_min (spurious, 0.0)."""
    d, i = _valid_min(scan, use_range_min=False)
    if i is None:
        return "No obstacle detected", False
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < threshold


def angle_without_angle_min(scan, threshold):
    """Angle as index * increment, forgetting angle_min."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", False
    return f"Min distance: {d:.3f} m, angle: {i * scan.angle_increment:.3f} rad", d < threshold


def angle_in_degrees(scan, threshold):
    """Reports degrees where the lab asks for radians."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", False
    a = math.degrees(scan.angle_min + i * scan.angle_increment)
    return f"Min distance: {d:.3f} m, angle: {a:.1f}", d < threshold


def crash_when_nothing_in_range(scan, threshold):
    """Indexes into an empty list when no return is valid."""
    valid = [
        (r, i)
        for i, r in enumerate(scan.ranges.tolist())
        if math.isfinite(r) and scan.range_min <= r <= scan.range_max
    ]
    d, i = min(valid)  # ValueError on an empty list
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < threshold


def no_bool(scan, threshold):
    """Never publishes the warning."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", None
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", None


def inverted_bool(scan, threshold):
    """Warns when the way is clear and not when it is not."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", True
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", not d < threshold


def threshold_hard_coded(scan, threshold):
    """Ignores the threshold it is given and uses the lab's 0.5 m."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", False
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < 0.5


def off_by_one_index(scan, threshold):
    """Reports the angle of the beam after the nearest one... twice over."""
    d, i = _valid_min(scan)
    if i is None:
        return "No obstacle detected", False
    a = scan.angle_min + (i + 2) * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < threshold
