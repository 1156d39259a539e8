"""How close a run came to failing, and how it failed (pure).

A hunt minimises the margin: below 0 for a failed run; for a passed one the
mean of three closenesses, each its ticks' smallest in [0, 1] (the answer
to its tolerance, the nearest return to the threshold, the share of valid
beams; docs/hunt.md). The mean, not the least, so no one of them (nothing in
range is easy to reach) holds the search. ``kinds`` names what the first
failing tick got wrong, so shrinking keeps a failure of the same kind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from harness.judge.oracle import Oracle, wrap
from harness.judge.records import RunResult, TickRecord
from harness.judge.status import half_unit

FAILED = -1.0  # the margin of a run that failed

#: What a failure's text starts with (or holds) -> its kind.
_KINDS = (
    ("expected warning", "warning"), ("expected distance", "distance"),
    ("gives no distance", "distance"), ("expected angle", "angle"),
    ("gives no angle", "angle"), ("claims an obstacle", "phantom obstacle"),
    ("expected an obstacle", "missed obstacle"),
)  # fmt: skip


@dataclass(frozen=True)
class Assessment:
    """What a hunt keeps of one run."""

    failed: bool
    margin: float  # FAILED when failed, else in [0, 1]
    kinds: tuple[str, ...]  # how the first failing tick failed, sorted; () when passed
    tick: int | None  # the first failing tick
    first_failure: str  # the run's first failure in words ("" when passed)
    ticks: int

    def same_way(self, other: Assessment) -> bool:
        """Did `other` fail as this one did (a kind in common)?"""
        return other.failed and bool(set(self.kinds) & set(other.kinds))


def assess(result: RunResult) -> Assessment:
    """The margin and the way of failing of `result`."""
    failed = result.failed_ticks
    if result.error is not None and result.broken:
        tick = failed[0].tick if failed else None
        return Assessment(True, FAILED, ("error",), tick, result.error, len(result.records))
    if failed:
        first = failed[0]
        return Assessment(
            True,
            FAILED,
            failure_kinds(first.verdict.failures),
            first.tick,
            result.first_failure or "; ".join(first.verdict.failures),
            len(result.records),
        )
    margin = run_margin([closeness(r, result.threshold) for r in result.records])
    return Assessment(False, margin, (), None, "", len(result.records))


def failure_kinds(failures: tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """A tick's failures' kinds, sorted; "answer" for none known (no status, several, late)."""
    kinds = set()
    for text in failures:
        kind = next((k for words, k in _KINDS if words in text), "answer")
        kinds.add(kind)
    return tuple(sorted(kinds))


def run_margin(ticks: list[tuple[float, float, float]]) -> float:
    """The mean over the three closenesses of their smallest over `ticks` (1 with none)."""
    if not ticks:
        return 1.0
    return sum(min(values) for values in zip(*ticks, strict=True)) / 3


def closeness(record: TickRecord, threshold: float) -> tuple[float, float, float]:
    """A passed tick's (answer, threshold, valid returns) closenesses (module docstring)."""
    exp, claim, scan = record.verdict.expected, record.verdict.claim, record.scan
    valid = _clip(scan.valid_mask().sum() / max(len(scan.ranges), 1) * 10)
    band = 1.0 if exp.distance is None else _clip(abs(exp.distance - threshold) / threshold)
    answer = 1.0
    if (
        claim is not None
        and claim.obstacle
        and exp.distance is not None
        and exp.angle is not None
        and claim.distance is not None
        and math.isfinite(claim.distance)
    ):
        tol = Oracle.distance_tolerance(exp.distance, claim.distance_decimals)
        ratio = _beyond_printing(abs(claim.distance - exp.distance), tol, claim.distance_decimals)
        if claim.angle is not None and math.isfinite(claim.angle):
            truths = [scan.angle_min + i * scan.angle_increment for i in exp.indices]
            off = min(abs(wrap(claim.angle - t)) for t in truths or [exp.angle])
            tol = Oracle.angle_tolerance(scan, claim.angle_decimals)
            ratio = max(ratio, _beyond_printing(off, tol, claim.angle_decimals))
        answer = _clip(1.0 - ratio)
    return answer, band, valid


def _beyond_printing(error: float, tolerance: float, decimals: int | None) -> float:
    """The part of `error` that printing to `decimals` places does not explain, as a
    share of the rest of `tolerance`: 0 for a right answer however it was rounded."""
    printing = half_unit(decimals)
    return max(0.0, error - printing) / max(tolerance - printing, 1e-12)


def _clip(value: float) -> float:
    return min(1.0, max(0.0, float(value)))
