"""Per-tick judgement of a node's answers against the scan it was sent (pure).

Only the *emitted* scan counts, the one the node received, so the truth
behind faults never leaks into a verdict. The rules and tolerances are
docs/oracle.md's ("What a correct node says", "Tolerances").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from harness.errors import ConfigError
from harness.faults.link import ON_TIME, Delivery
from harness.judge.answers import Answers
from harness.judge.status import StatusClaim, compile_status_pattern, half_unit, parse_status
from harness.lidar.scan import Scan
from harness.safe_text import QUOTE_LIMIT, TEXT_LIMIT, clip, for_storage

__all__ = ["Expectation", "Oracle", "Verdict", "summarise_scan", "wrap"]

_EPS32 = float(np.finfo(np.float32).eps)
ABS_DISTANCE_TOL = 1e-6  # metres, on top of printed precision and float32 rounding
ABS_ANGLE_TOL = 1e-5  # radians: float32 angle_min/increment times a few hundred beams
MIN_BAND = 0.005  # metres either side of the threshold
CAME_LATE = "; it came after"  # a missed deadline whose answer did come: late, not silent


@dataclass(frozen=True)
class Expectation:
    """What a correct node says about one scan."""

    obstacle: bool  # any valid reading
    distance: float | None  # min valid reading (as float32 -> float)
    angle: float | None  # angle_min + index * angle_increment
    index: int | None  # first beam holding the minimum
    warning: bool | None  # None: inside the threshold band, either answer accepted
    indices: tuple[int, ...] = ()  # every beam holding exactly the minimum (ties)
    may_be_clear: bool = False  # only readings exactly at range_max: "no obstacle" passes too


@dataclass(frozen=True)
class Verdict:
    """The judgement of one tick; ``explanation`` is empty when ok."""

    tick: int
    t: float
    ok: bool
    expected: Expectation
    claim: StatusClaim | None
    warning_got: bool | None
    failures: tuple[str, ...]
    explanation: str

    def clipped(self, limit: int = TEXT_LIMIT) -> Verdict:
        """A copy to keep in a record: its texts clipped to `limit` (length noted), as UTF-8."""
        claim = self.claim
        if claim is not None:
            claim = replace(claim, text=for_storage(claim.text, limit))
        return replace(
            self,
            claim=claim,
            failures=tuple(for_storage(f, limit) for f in self.failures),
            explanation=for_storage(self.explanation, limit),
        )


def _quoted(text: str) -> str:
    """A status as an explanation quotes it: repr, and only its start when long.

    The oracle judged the whole text; the explanation notes its length.
    """
    return repr(clip(text, QUOTE_LIMIT))


def _num(x: float | None, places: int = 3) -> str:
    """A reading for humans: up to `places` decimals, at least two; inf/nan by name."""
    if x is None:
        return "none"
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    text = f"{x:.{places}f}"
    whole, _, frac = text.partition(".")
    frac = frac.rstrip("0").ljust(2, "0")
    return f"{whole}.{frac}"


def summarise_scan(scan: Scan) -> str:
    """Counts of each kind of reading, e.g. '300 valid, 58 +inf, 2 NaN'."""
    r = scan.ranges
    valid = scan.valid_mask()
    rmin, rmax = np.float32(scan.range_min), np.float32(scan.range_max)
    finite = np.isfinite(r)
    invalid_finite = finite & ~valid
    parts = [
        (int(valid.sum()), "valid"),
        (int(np.sum(r == np.inf)), "+inf"),
        (int(np.sum(r == -np.inf)), "-inf"),
        (int(np.isnan(r).sum()), "NaN"),
        (int(np.sum(invalid_finite & (r == 0))), "zero"),
        (int(np.sum(invalid_finite & (r < 0))), "negative"),
        (int(np.sum(invalid_finite & (r > 0) & (r < rmin))), "below range_min"),
        (int(np.sum(invalid_finite & (r > rmax))), "above range_max"),
    ]
    text = ", ".join(f"{n} {what}" for n, what in parts if n)
    at_max = int(np.sum(valid & (r == rmax)))
    if at_max:
        text = text.replace("valid", f"valid ({at_max} at range_max)", 1)
    return text or "no beams"


def expect(scan: Scan, threshold: float, band: float) -> Expectation:
    """The expectation for one scan (see the module docstring)."""
    valid = scan.valid_mask()
    if not valid.any():
        return Expectation(False, None, None, None, False)
    r = scan.ranges
    lowest = r[valid].min()
    indices = tuple(int(i) for i in np.flatnonzero(valid & (r == lowest)))
    distance = float(lowest)
    index = indices[0]
    if band > 0 and abs(distance - threshold) <= band:
        warning: bool | None = None
    else:
        warning = distance < threshold
    angle = scan.angle_min + index * scan.angle_increment
    at_max = bool(lowest == np.float32(scan.range_max))
    return Expectation(True, distance, angle, index, warning, indices, may_be_clear=at_max)


def wrap(x: float) -> float:
    """x folded into [-pi, pi)."""
    return (x + math.pi) % (2 * math.pi) - math.pi


class Oracle:
    """Judges each tick: the status text, the warning Bool, and how they arrived."""

    def __init__(
        self,
        threshold: float,
        *,
        band: float | None = None,
        noise_sigma: float = 0.0,
        status_pattern: str | None = None,
        warning_required_when_clear: bool = False,
        require_angle: bool = True,
    ) -> None:
        if not (math.isfinite(threshold) and threshold > 0):
            raise ConfigError(f"threshold must be a positive number of metres, got {threshold}")
        if band is not None and not (math.isfinite(band) and band >= 0):
            raise ConfigError(f"threshold band must be >= 0 m, got {band}")
        self.threshold = float(threshold)
        self.band = (
            float(band)
            if band is not None
            else max(MIN_BAND, 3.0 * noise_sigma, 4 * _EPS32 * threshold)
        )
        self.pattern = compile_status_pattern(status_pattern)
        self.warning_required_when_clear = warning_required_when_clear
        self.require_angle = require_angle

    def expect(self, scan: Scan) -> Expectation:
        """What a correct node says about `scan`."""
        return expect(scan, self.threshold, self.band)

    # -- tolerances --------------------------------------------------------

    @staticmethod
    def distance_tolerance(expected: float, decimals: int | None) -> float:
        """Half a printed unit + float32 rounding + a hair."""
        return half_unit(decimals) + 4 * _EPS32 * abs(expected) + ABS_DISTANCE_TOL

    @staticmethod
    def angle_tolerance(scan: Scan, decimals: int | None) -> float:
        """One beam either way + half a printed unit + float32 angle arithmetic."""
        return scan.angle_increment * (1 + 1e-6) + half_unit(decimals) + ABS_ANGLE_TOL

    @staticmethod
    def angle_matches(claimed: float, truth: float, tol: float, decimals: int | None) -> bool:
        """Is `claimed` the angle `truth` (radians), in this or another standard wrap?

        Within `tol` of truth, or of truth +- 2*pi while the claim stays within
        [-2*pi, 2*pi]. A claim matching truth in degrees fails first: otherwise a
        node printing degrees would pass now and then.
        """
        if not math.isfinite(claimed):
            return False
        if abs(claimed - truth) <= tol:
            return True
        if _is_degrees(claimed, truth, tol, decimals) or abs(claimed) > 2 * math.pi + tol:
            return False
        return any(abs(claimed - (truth + k * 2 * math.pi)) <= tol for k in (-1, 1))

    # -- judgement ---------------------------------------------------------

    def judge(
        self, tick: int, t: float, scan: Scan, answers: Answers, delivery: Delivery = ON_TIME
    ) -> Verdict:
        """Judge one tick; failures accumulate so one verdict names every problem.

        A dropped scan expects no answer; a duplicate, reordered or stale one
        (`delivery`) may go unanswered; an answer that comes must be right.
        """
        exp = self.expect(scan)
        failures: list[str] = []
        if answers.problem:  # a node that died says how, with its last words: that is all
            failures.append(
                clip(answers.problem)
                if answers.crashed or answers.silent
                else f"link problem: {clip(answers.problem)}"
            )

        texts = [str(r.value) for r in answers.statuses]
        claim: StatusClaim | None = None
        skipped = not texts and not answers.warnings and not answers.problem
        if not delivery.delivered or answers.lost is not None:
            return Verdict(tick, t, not failures, exp, None, None, tuple(failures), "")
        if skipped and delivery.may_be_ignored:
            return Verdict(tick, t, True, exp, None, None, (), "")
        if not texts:
            if answers.timed_out:
                came = [r for r in answers.late if r.tick == tick and isinstance(r.value, str)]
                late = ""
                if came:
                    late = f"{CAME_LATE} {came[0].after:.2f} s: {_quoted(str(came[0].value))}"
                failures.append(f"no status within the deadline ({answers.waited:.2f} s){late}")
            elif not answers.crashed:
                failures.append("no status arrived")
        else:
            if len(texts) > 1:
                quoted = ", ".join(_quoted(x) for x in texts[:4])
                times = "twice" if len(texts) == 2 else f"{len(texts)} times"
                failures.append(f"answered {times} (one status per scan expected): {quoted}")
            claim = parse_status(texts[0], self.pattern)
            failures.extend(self.claim_failures(scan, exp, claim))

        bools = [r.value for r in answers.warnings if isinstance(r.value, bool)]
        warning_got = bools[-1] if bools else None
        failures.extend(self.warning_failures(exp, warning_got))
        for earlier_scan, earlier in answers.earlier:  # each answer against the scan it answered
            sub = self.judge(tick, t, earlier_scan, earlier)
            failures.extend(f"answering an earlier driver scan: {f}" for f in sub.failures)

        explanation = ""
        if failures:
            how = delivery.describe()
            if answers.extra_scans:
                n = 1 + answers.extra_scans
                how = ", ".join(
                    filter(None, [how, f"the driver published {n} scans in this exchange"])
                )
            where = f"t={t:.2f} s tick {tick}" + (f" ({how})" if how else "")
            explanation = f"{where}: {self._context(scan, exp)}; " + "; ".join(failures)
        ok = not failures
        return Verdict(tick, t, ok, exp, claim, warning_got, tuple(failures), explanation)

    def _context(self, scan: Scan, exp: Expectation) -> str:
        thr = f"threshold {_num(self.threshold, 2)} m"
        if not exp.obstacle:
            return f"expected no obstacle (no valid return: {summarise_scan(scan)}); {thr}"
        beam = f"beam {exp.index}"
        if len(exp.indices) > 1:
            others = ", ".join(str(i) for i in exp.indices[1:6])
            more = ", ..." if len(exp.indices) > 6 else ""
            also = "beam" if len(exp.indices) == 2 else "beams"
            beam += f"; also {also} {others}{more}"
        text = f"nearest valid return {_num(exp.distance)} m at {_num(exp.angle)} rad ({beam})"
        if exp.may_be_clear:
            text += " = range_max, so 'no obstacle' is accepted too"
        band = f" ± {_num(self.band)} band" if exp.warning is None else ""
        return f"{text}; {thr}{band}"

    def claim_failures(self, scan: Scan, exp: Expectation, claim: StatusClaim) -> list[str]:
        """What is wrong with `claim` as the status for `scan` (empty: it passes); the
        run's hints ask this of answers against other ticks' scans."""
        quoted = _quoted(claim.text)
        if claim.unreadable:  # what it claims is unknown: wrong whatever the scan
            return [f"cannot read status {quoted}: {claim.unreadable}"]
        if not exp.obstacle:
            if claim.obstacle:
                at = f" at {_num(claim.distance)} m" if claim.distance is not None else ""
                return [f"status {quoted} claims an obstacle{at}"]
            return []
        if not claim.obstacle:
            if exp.may_be_clear:
                return []
            why = f" ({claim.reason})" if claim.reason else ""
            return [
                f"expected an obstacle at {_num(exp.distance)} m; status {quoted} claims none{why}"
            ]
        out: list[str] = []
        assert exp.distance is not None and exp.angle is not None
        if claim.distance is None:
            out.append(f"status {quoted} gives no distance (expected {_num(exp.distance)} m)")
        else:
            tol = self.distance_tolerance(exp.distance, claim.distance_decimals)
            if not (math.isfinite(claim.distance) and abs(claim.distance - exp.distance) <= tol):
                out.append(
                    f"expected distance {_num(exp.distance, 4)} m (± {tol:.2g});"
                    f" status {quoted} gives {_num(claim.distance, 4)} m"
                    + _distance_hint(scan, exp.distance, claim.distance, tol)
                )
        if claim.angle is None:
            if self.require_angle:
                out.append(f"status {quoted} gives no angle (expected {_num(exp.angle)} rad)")
            return out
        tol = self.angle_tolerance(scan, claim.angle_decimals)
        truths = [scan.angle_min + i * scan.angle_increment for i in exp.indices]
        ok = any(self.angle_matches(claim.angle, a, tol, claim.angle_decimals) for a in truths)
        if not ok:
            out.append(
                f"expected angle {_num(exp.angle, 4)} rad (give or take {tol:.2g} rad; "
                "-pi..pi and 0..2pi both accepted);"
                f" status {quoted} gives {_num(claim.angle, 4)}"
                + _angle_hint(scan, truths, claim.angle, claim.angle_decimals)
            )
        return out

    def warning_failures(self, exp: Expectation, got: bool | None) -> list[str]:
        """What is wrong with the Bool `got` for a scan expecting `exp` (empty: it passes)."""
        if exp.warning is None:
            return []
        shown = "no Bool" if got is None else str(got)
        if exp.warning and got is not True:
            return [f"expected warning True; got {shown}"]
        if not exp.warning:
            if got is True:
                return ["expected warning False (or none); got True"]
            if got is None and self.warning_required_when_clear:
                return ["expected warning False; got no Bool"]
        return []


def _distance_hint(scan: Scan, expected: float, claimed: float, tol: float) -> str:
    """Name the likely mistake behind a wrong distance, if one fits."""
    if not math.isfinite(claimed):
        return " (a non-finite distance while a valid return exists)"
    for factor, unit in ((100.0, "centimetres"), (1000.0, "millimetres")):
        if abs(claimed - expected * factor) <= tol * factor + 0.5:
            return f" (looks like {unit})"
    r = scan.ranges.astype(np.float64)  # a huge claim must not overflow float32
    bad = np.flatnonzero(np.isfinite(r) & ~scan.valid_mask() & (np.abs(r - claimed) <= tol))
    if bad.size:
        i = int(bad[0])
        where = "below range_min" if r[i] < scan.range_min else "above range_max"
        return f" (that is beam {i}'s invalid reading, {where})"
    return ""


def _angle_hint(scan: Scan, truths: list[float], claimed: float, decimals: int | None) -> str:
    """Spot degrees, a forgotten angle_min and index-for-angle mistakes."""
    if not math.isfinite(claimed):
        return ""
    tol = Oracle.angle_tolerance(scan, decimals)
    for a in truths:
        if _is_degrees(claimed, a, tol, decimals):
            return f" (looks like degrees: {_num(a, 4)} rad is {math.degrees(a):.1f}°)"
    indices = _indices_of(scan, truths)
    if abs(scan.angle_min) > tol and any(
        abs(claimed - i * scan.angle_increment) <= tol for i in indices
    ):
        return (
            " (the angle looks measured from beam 0, without angle_min "
            f"({_num(scan.angle_min)} rad here))"
        )
    index_tol = 1 + half_unit(decimals)
    if any(abs(claimed - i) <= index_tol for i in indices):
        return " (looks like the beam index, not its angle)"
    if any(abs(wrap(claimed - a)) <= scan.angle_increment * 1.5 for a in truths):
        return " (right direction, but outside [-2*pi, 2*pi])"
    return ""


def _is_degrees(claimed: float, truth: float, tol: float, decimals: int | None) -> bool:
    """`claimed` is `truth` in degrees (any of three wraps) and radians would differ."""
    if abs(claimed - truth) <= tol:
        return False  # near 0 both readings agree: not evidence of degrees
    deg_tol = math.degrees(tol - half_unit(decimals)) + half_unit(decimals) + 1e-3
    deg = math.degrees(truth)
    return min(abs(claimed - (deg + k * 360.0)) for k in (-1, 0, 1)) <= deg_tol


def _indices_of(scan: Scan, truths: list[float]) -> list[int]:
    return [round((a - scan.angle_min) / scan.angle_increment) for a in truths]
