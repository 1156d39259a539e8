"""Right processing functions whose status is a structure, as students print one.

Each is ``fn(scan, threshold) -> (status, warning)`` for the inprocess link,
and each says "nothing in range" its format's way: json.dumps's
``Infinity``, str() of a dict's ``inf``, YAML's ``.inf``. The suite must
pass them all (tests/test_status_structured_e2e.py).
"""

from __future__ import annotations

import json
import math


def _nearest(scan):
    """The minimum valid reading and its angle; (inf, None) when none is valid."""
    best, index = math.inf, None
    for i, r in enumerate(scan.ranges.tolist()):
        if math.isfinite(r) and scan.range_min <= r <= scan.range_max and r < best:
            best, index = r, i
    if index is None:
        return math.inf, None
    return best, scan.angle_min + index * scan.angle_increment


def json_with_infinity(scan, threshold):
    """json.dumps of the raw minimum: Infinity and null when nothing is in range."""
    d, a = _nearest(scan)
    status = json.dumps({"obstacle": a is not None, "min_distance": d, "angle": a})
    return status, d < threshold


def printed_dict(scan, threshold):
    """str() of a dict: {'obstacle': False, 'distance': inf, 'angle': None} when clear."""
    d, a = _nearest(scan)
    return str({"obstacle": a is not None, "distance": d, "angle": a}), d < threshold


def yaml_lines(scan, threshold):
    """key: value lines, YAML's .inf and null when clear, units after the numbers."""
    d, a = _nearest(scan)
    if a is None:
        return "obstacle: false\ndistance: .inf\nangle: null", False
    return f"obstacle: true\ndistance: {d:.3f} m\nangle: {a:.3f} rad", d < threshold
