"""Reading coverage: which kinds of readings a suite's delivered scans carry (pure).

Counted from the scans the node received (a dropped or lost scan is not
one), never from the scenario files, so an instructor sees what the suite
really exercises; validity is the oracle's. Per scan:

* ``cases``: a reading of the case (``CASES``: nan, +-inf, zero where
  invalid, below range_min, above range_max), ``beside_valid`` or
  ``without_valid`` a valid reading in the same scan;
* ``near_threshold``: its nearest valid return outside the oracle's band but
  within ``NEAR_THRESHOLD_M`` of its edge, where a node that rounds before
  comparing, or a threshold a few centimetres off, warns wrong;
* ``angle_near_pi``: that return's angle within ``ANGLE_MARGIN_RAD`` of +-pi
  in the scan's own wrap (the seam of the angle range);
* ``angle_min_zero`` / ``angle_min_minus_pi``: the scan's angle_min.

Per run, in order: ``warning_clears``, how often a due warning (outside the
band) becomes not due on a later scan: what shows a latched warning.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan

__all__ = [
    "ANGLE_MARGIN_RAD", "CASES", "NEAR_THRESHOLD_M", "ReadingCoverage", "band_of",
    "coverage_by_scenario", "coverage_of", "delivered_scans", "gaps", "other_counts",
]  # fmt: skip

CASES = ("nan", "pos_inf", "neg_inf", "zero", "below_range_min", "above_range_max")
CASE_NAMES = {  # each case as reports name it
    "nan": "NaN", "pos_inf": "+inf", "neg_inf": "-inf", "zero": "0.0",
    "below_range_min": "below range_min (0 < r < range_min)",
    "above_range_max": "above range_max (finite)",
}  # fmt: skip
NEAR_THRESHOLD_M = 0.1  # beyond the band's edge, either side of the threshold
ANGLE_MARGIN_RAD = 0.2  # of +pi or -pi
ANGLE_MIN_TOL = 1e-6  # angle_min 0 or -pi within this

# What a suite without each case lets pass, in plain words (gaps()).
_CASE_GAPS: dict[tuple[str, bool], str] = {
    ("nan", True): "no scan has NaN beside a valid return: "
    "a node that filters inf but not NaN passes",
    ("nan", False): "no scan has NaN and no valid return: "
    "a node that reports 'nan m' (or crashes) when only NaN comes back passes",
    ("pos_inf", True): "no scan has +inf beside a valid return: "
    "a node that lets an out-of-range beam spoil its minimum passes",
    ("pos_inf", False): "no scan has +inf and no valid return (nothing in range): "
    "a node that reports 'inf m' or crashes on an empty list passes",
    ("neg_inf", True): "no scan has -inf beside a valid return: "
    "a node that filters only +inf (so min() picks -inf) passes",
    ("neg_inf", False): "no scan has -inf and no valid return: "
    "a node that reports '-inf m' when nothing is in range passes",
    ("zero", True): "no scan has a 0.0 reading beside a valid return: "
    "a node that does not check range_min (and reports 0 m) passes",
    ("zero", False): "no scan has a 0.0 reading and no valid return: "
    "a node that takes 0.0 for an obstacle when nothing is in range passes",
    ("below_range_min", True): "no scan has a reading below range_min beside a valid return: "
    "a node that ignores range_min passes",
    ("below_range_min", False): "no scan has a reading below range_min and no valid return: "
    "a node that ignores range_min and claims an obstacle when none is in range passes",
    ("above_range_max", True): "no scan has a finite reading above range_max beside "
    "a valid return: how a node treats such readings next to real returns is untested",
    ("above_range_max", False): "no scan has a finite reading above range_max and no valid "
    "return: a node that ignores range_max and claims a far obstacle passes",
}
_OTHER_GAPS: dict[str, str] = {
    "near_threshold": "no scan's nearest valid return lies just outside the threshold band "
    f"(within {NEAR_THRESHOLD_M:g} m of its edge): a node that rounds before comparing, or "
    "uses a threshold a few centimetres off, passes",
    "angle_near_pi": "no scan's nearest valid return lies within "
    f"{ANGLE_MARGIN_RAD:g} rad of +pi or -pi (behind the LIDAR's zero): a node whose angle "
    "is wrong at the seam of the angle range passes",
    "angle_min_zero": "no scan has angle_min 0: "
    "a node that assumes angle_min = -pi (angle = -pi + i * increment) passes",
    "angle_min_minus_pi": "no scan has angle_min -pi: "
    "a node that assumes angle_min = 0 (angle = i * increment) passes",
    "warning_clears": "no run clears a due warning (the nearest return moving back beyond "
    "the threshold): a node that latches its warning True passes",
}


def _zeros() -> dict[str, int]:
    return dict.fromkeys(CASES, 0)


@dataclass
class _Features:
    """Per-scan facts, arrays in the order the scans came."""

    has_valid: np.ndarray  # bool (n,)
    distance: np.ndarray  # float64 (n,): min valid, nan without one
    angle: np.ndarray  # float64 (n,): angle of the first beam holding it, nan without one
    hits: np.ndarray  # bool (n, len(CASES))


def _features(scans: Sequence[Scan]) -> _Features:
    """Each scan's facts; scans of one size are stacked and computed at once."""
    n = len(scans)
    has_valid = np.zeros(n, bool)
    distance = np.full(n, np.nan)
    angle = np.full(n, np.nan)
    hits = np.zeros((n, len(CASES)), bool)
    by_size: dict[int, list[int]] = {}
    for i, scan in enumerate(scans):
        by_size.setdefault(scan.ranges.size, []).append(i)
    for size, members in by_size.items():
        if size == 0:
            continue
        idx = np.asarray(members)
        r = np.stack([scans[i].ranges for i in members])  # float32 (m, size)
        # float32 limits: compared as Scan.valid_mask compares them
        rmin = np.array([scans[i].range_min for i in members], np.float32)[:, None]
        rmax = np.array([scans[i].range_max for i in members], np.float32)[:, None]
        with np.errstate(invalid="ignore"):
            finite = np.isfinite(r)
            valid = finite & (r >= rmin) & (r <= rmax)
            odd = finite & ~valid  # finite but invalid
            cases = (
                np.isnan(r),
                r == np.inf,
                r == -np.inf,
                odd & (r == 0),
                odd & (r > 0) & (r < rmin),
                odd & (r > rmax),
            )
        hits[idx] = np.stack([c.any(axis=1) for c in cases], axis=1)
        masked = np.where(valid, r, np.float32(np.inf))
        first = masked.argmin(axis=1)  # the first beam holding the minimum
        lowest = masked[np.arange(len(members)), first].astype(np.float64)
        some = valid.any(axis=1)
        angle_min = np.array([scans[i].angle_min for i in members], np.float64)
        increment = np.array([scans[i].angle_increment for i in members], np.float64)
        has_valid[idx] = some
        distance[idx] = np.where(some, lowest, np.nan)
        angle[idx] = np.where(some, angle_min + first * increment, np.nan)
    return _Features(has_valid, distance, angle, hits)


@dataclass
class ReadingCoverage:
    """Counts of scans carrying each kind of reading (the module docstring defines them)."""

    scans: int = 0
    beside_valid: dict[str, int] = field(default_factory=_zeros)
    without_valid: dict[str, int] = field(default_factory=_zeros)
    near_threshold: int = 0
    angle_near_pi: int = 0
    angle_min_zero: int = 0
    angle_min_minus_pi: int = 0
    warning_clears: int = 0

    def add(self, scans: Sequence[Scan], threshold: float, band: float) -> ReadingCoverage:
        """Count one run's delivered `scans`, in the order the node received them
        (warnings cleared are counted within this run only); returns self."""
        if not scans:
            return self
        f = _features(scans)
        valid = f.has_valid
        for k, case in enumerate(CASES):
            self.beside_valid[case] += int(np.sum(f.hits[:, k] & valid))
            self.without_valid[case] += int(np.sum(f.hits[:, k] & ~valid))
        with np.errstate(invalid="ignore"):  # nan where a scan has no valid return
            off = np.abs(f.distance - threshold)
            in_band = valid & (off <= band) if band > 0 else np.zeros_like(valid)
            outside = valid & ~in_band
            self.near_threshold += int(np.sum(outside & (off <= band + NEAR_THRESHOLD_M)))
            due = outside & (f.distance < threshold)
            clear = ~valid | (outside & (f.distance >= threshold))
            wrapped = np.remainder(f.angle + math.pi, 2 * math.pi) - math.pi  # [-pi, pi)
            self.angle_near_pi += int(
                np.sum(valid & (math.pi - np.abs(wrapped) <= ANGLE_MARGIN_RAD))
            )
        angle_min = np.array([s.angle_min for s in scans], np.float64)
        self.angle_min_zero += int(np.sum(np.abs(angle_min) <= ANGLE_MIN_TOL))
        self.angle_min_minus_pi += int(np.sum(np.abs(angle_min + math.pi) <= ANGLE_MIN_TOL))
        state = np.where(due, 1, np.where(clear, 0, -1))
        state = state[state >= 0]  # scans in the band leave the warning as it was
        self.warning_clears += int(np.sum((state[:-1] == 1) & (state[1:] == 0)))
        self.scans += len(scans)
        return self

    def add_result(self, result: RunResult) -> ReadingCoverage:
        """Count one run's delivered scans, with its threshold and the oracle's band."""
        scans = delivered_scans(result.records)
        if scans:
            self.add(scans, result.threshold, band_of(result))
        return self

    def merge(self, other: ReadingCoverage) -> ReadingCoverage:
        """Add `other`'s counts to these; returns self."""
        for case in CASES:
            self.beside_valid[case] += other.beside_valid[case]
            self.without_valid[case] += other.without_valid[case]
        for name in ("scans", *_OTHER_GAPS):  # the counts beside the cases
            setattr(self, name, getattr(self, name) + getattr(other, name))
        return self

    def as_dict(self) -> dict[str, Any]:
        """A stable JSON shape: scans, cases (each beside_valid / without_valid), the rest."""
        return {
            "scans": self.scans,
            "cases": {
                case: {
                    "beside_valid": self.beside_valid[case],
                    "without_valid": self.without_valid[case],
                }
                for case in CASES
            },
            **{name: getattr(self, name) for name in _OTHER_GAPS},
        }


def delivered_scans(records: Iterable[TickRecord]) -> list[Scan]:
    """The scans the node received: not dropped by the link, not lost on the line."""
    return [r.scan for r in records if r.delivery.delivered and r.answers.lost is None]


def band_of(result: RunResult) -> float:
    """The band around the threshold in which the run's oracle accepted either warning."""
    return Oracle(result.threshold, noise_sigma=result.noise_sigma).band


def coverage_of(results: Sequence[RunResult]) -> ReadingCoverage:
    """The whole suite's coverage."""
    total = ReadingCoverage()
    for result in results:
        total.add_result(result)
    return total


def coverage_by_scenario(results: Sequence[RunResult]) -> dict[str, ReadingCoverage]:
    """Each scenario's coverage, in run order (runs of one name are summed)."""
    out: dict[str, ReadingCoverage] = {}
    for result in results:
        out.setdefault(result.scenario, ReadingCoverage()).add_result(result)
    return out


def gaps(coverage: ReadingCoverage) -> list[str]:
    """What the suite never delivers, one plain line per missing item (empty: nothing missing)."""
    if coverage.scans == 0:
        return ["no scan was delivered: the suite shows nothing about how a node reads scans"]
    out = []
    for case in CASES:
        if not coverage.beside_valid[case]:
            out.append(_CASE_GAPS[case, True])
        if not coverage.without_valid[case]:
            out.append(_CASE_GAPS[case, False])
    for name, line in _OTHER_GAPS.items():
        if not getattr(coverage, name):
            out.append(line)
    return out


def other_counts(total: Mapping[str, Any]) -> list[tuple[str, int]]:
    """An ``as_dict()``'s counts beside the six cases, each with its words, for reports."""
    return [
        (
            f"scans whose nearest valid return lies outside the threshold band, within "
            f"{NEAR_THRESHOLD_M:g} m of its edge",
            total["near_threshold"],
        ),
        (
            f"scans whose nearest valid return lies within {ANGLE_MARGIN_RAD:g} rad of +pi or -pi",
            total["angle_near_pi"],
        ),
        ("scans with angle_min 0", total["angle_min_zero"]),
        ("scans with angle_min -pi", total["angle_min_minus_pi"]),
        ("times a due warning stopped being due later in its run", total["warning_clears"]),
    ]
