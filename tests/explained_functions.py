"""Processing functions with mistakes only the whole run explains (tests/test_explanations.py).

Each is ``fn(scan, threshold) -> (status, warning)`` for the inprocess link,
whose child process lives for one scenario, so module state lasts a run.
"""

from __future__ import annotations

import math

_state: dict[str, object] = {}


def _nearest(scan):
    best, index = math.inf, None
    for i, r in enumerate(scan.ranges.tolist()):
        if math.isfinite(r) and scan.range_min <= r <= scan.range_max and r < best:
            best, index = r, i
    return best, index


def _answer(scan, threshold):
    d, i = _nearest(scan)
    if i is None:
        return "No obstacle", False
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", d < threshold


def one_scan_late(scan, threshold):
    """Publishes the result it stored for the scan before, then computes this one's."""
    answer = _state.get("previous", ("No obstacle", False))
    _state["previous"] = _answer(scan, threshold)
    return answer


def rounds_before_compare(scan, threshold):
    """Compares the distance rounded to one decimal: round(0.46, 1) < 0.5 is False."""
    d, i = _nearest(scan)
    if i is None:
        return "No obstacle", False
    a = scan.angle_min + i * scan.angle_increment
    return f"Min distance: {d:.3f} m, angle: {a:.3f} rad", round(d, 1) < threshold


def latched_warning(scan, threshold):
    """Once it warned, it warns for ever."""
    status, warning = _answer(scan, threshold)
    _state["latched"] = bool(_state.get("latched")) or bool(warning)
    return status, bool(_state["latched"])
