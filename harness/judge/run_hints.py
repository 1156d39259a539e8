"""Hints drawn from a whole run, for mistakes no single tick reveals (pure).

One tick says what was wrong, not why; the run often can. Each hint names a
mistake only when the whole run fits it (the table in docs/oracle.md, "Hints
from the whole run"); `run_hint` gives them in that order, and a node one
scan late gets no threshold hint (its Bools are the scan before's).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from harness.judge.oracle import CAME_LATE, Oracle, Verdict
from harness.lidar.scan import Scan

WARNING_FAILURE = "expected warning"
NO_STATUS = "no status within the deadline"  # it was running, and said nothing
NO_BOOL_WHEN_TRUE = "expected warning True; got no Bool"
LATE_SHARE = 0.75  # this share of the comparable failed ticks must fit the scan before
ROUNDED_DECIMALS = (1, 2)


def run_hint(
    verdicts: Sequence[Verdict],
    threshold: float,
    *,
    scans: Sequence[Scan] | None = None,
    noise_sigma: float = 0.0,
) -> str | None:
    """Every hint the run gives, 'hint: ...; hint: ...', or None. `scans` are the scans
    the verdicts judged (the same order); without them the hints that re-judge an
    answer against another scan are not tried."""
    if all(v.ok for v in verdicts):
        return None
    oracle = Oracle(threshold, noise_sigma=noise_sigma, require_angle=False)
    hints: list[str | None] = []
    late = None
    if scans is not None and len(scans) == len(verdicts):
        late = one_scan_late_hint(verdicts, scans, oracle)
        hints.append(late)
        hints.append(silent_when_clear_hint(verdicts) or on_change_hint(verdicts, scans, oracle))
    else:
        hints.append(silent_when_clear_hint(verdicts))
    hints.append(latched_warning_hint(verdicts))
    if late is None:
        hints.append(rounding_hint(verdicts, threshold) or threshold_hint(verdicts, threshold))
    hints.append(first_answer_hint(verdicts))
    shown = [h for h in hints if h]
    return "; ".join(shown) if shown else None


def _ticks(ticks: Sequence[int]) -> str:
    """'tick 4', 'ticks 4 and 9', 'ticks 4-6', 'ticks 4, 7, 9, ...' for a hint."""
    if len(ticks) == 1:
        return f"tick {ticks[0]}"
    if list(ticks) == list(range(ticks[0], ticks[0] + len(ticks))):
        return f"ticks {ticks[0]}-{ticks[-1]}"
    if len(ticks) == 2:
        return f"ticks {ticks[0]} and {ticks[1]}"
    more = ", ..." if len(ticks) > 4 else ""
    return "ticks " + ", ".join(str(t) for t in ticks[:4]) + more


# -- one scan late ---------------------------------------------------------------


def _right_for(v: Verdict, scan: Scan, earlier: Verdict, oracle: Oracle) -> bool:
    """Would `v`'s answers have passed as answers to `earlier`'s scan?"""
    if v.claim is None:
        return False
    exp = earlier.expected
    wrong = oracle.claim_failures(scan, exp, v.claim) + oracle.warning_failures(exp, v.warning_got)
    return not wrong


def one_scan_late_hint(
    verdicts: Sequence[Verdict], scans: Sequence[Scan], oracle: Oracle
) -> str | None:
    """'the answers match the previous scan's', when most failed ticks with a status
    would have been right for the tick before (and it expected something else)."""
    comparable, late = [], []
    for i in range(1, len(verdicts)):
        earlier, v = verdicts[i - 1], verdicts[i]
        if v.ok or v.claim is None or earlier.tick != v.tick - 1:
            continue
        if earlier.expected == v.expected:
            continue  # the same answer was due: nothing tells late from wrong
        comparable.append(v.tick)
        if _right_for(v, scans[i - 1], earlier, oracle):
            late.append(v.tick)
    if len(late) < 2 or len(late) < LATE_SHARE * len(comparable):
        return None
    return (
        f"hint: the answers match the previous scan's ({len(late)} of the "
        f"{len(comparable)} failed ticks with a status, from tick {late[0]}): is the node "
        "answering one scan late (e.g. publishing a stored result before computing the new one)?"
    )


# -- silence ------------------------------------------------------------------------


def _silent(v: Verdict) -> bool:
    """No status by the deadline, nor later (a late one is slow, not silent)."""
    return v.claim is None and any(
        f.startswith(NO_STATUS) and CAME_LATE not in f for f in v.failures
    )


def silent_when_clear_hint(verdicts: Sequence[Verdict]) -> str | None:
    """No status for any scan with no valid return, every other scan answered."""
    silent = [v.tick for v in verdicts if _silent(v)]
    if not silent:
        return None
    clear = [v for v in verdicts if not v.expected.obstacle]
    if any(v.claim is not None for v in clear):
        return None  # it does answer such scans
    if any(_silent(v) for v in verdicts if v.expected.obstacle):
        return None
    if not any(v.claim is not None for v in verdicts):
        return None  # silent throughout: nothing says it is about empty scans
    return (
        f"hint: the node published no status for the scans with no valid return ({_ticks(silent)})"
        ' and answered the others: a status is expected when nothing is in range too (e.g. "no '
        'obstacle")'
    )


def on_change_hint(
    verdicts: Sequence[Verdict], scans: Sequence[Scan], oracle: Oracle
) -> str | None:
    """Silent exactly where its last status (or Bool) still held: it publishes on change."""
    hints = []
    last: Verdict | None = None  # the latest tick with a status
    held: list[int] = []
    other = False
    held_since: Verdict | None = None  # the status that still held at the first silent tick
    for v, scan in zip(verdicts, scans, strict=True):
        if _silent(v) and last is not None and last.claim is not None:
            if oracle.claim_failures(scan, v.expected, last.claim):
                other = True
            else:
                held.append(v.tick)
                held_since = held_since or last
        if v.claim is not None:
            last = v
    if held and not other and held_since is not None and held_since.claim is not None:
        hints.append(
            f"hint: the node published no status at {_ticks(held)}, where its last status "
            f"({held_since.claim.text!r}, tick {held_since.tick}) still held: it looks like it "
            "publishes its status only when it changes, but a status is expected for every scan"
        )
    bool_held, bool_other = [], []
    last_bool: bool | None = None
    for v in verdicts:
        if NO_BOOL_WHEN_TRUE in v.failures and v.claim is not None:
            (bool_held if last_bool is True else bool_other).append(v.tick)
        if v.warning_got is not None:
            last_bool = v.warning_got
    if bool_held and not bool_other:
        hints.append(
            f"hint: no Bool came at {_ticks(bool_held)}, while its last Bool, True, still held: "
            "it looks like it publishes its warning only when it changes, but warning True is "
            "expected with every scan that has an obstacle within the threshold"
        )
    return "; ".join(hints) or None


# -- warnings -----------------------------------------------------------------------


def latched_warning_hint(verdicts: Sequence[Verdict]) -> str | None:
    """'warning True since tick N and never cleared', when the Bool stayed True to the
    end of the run, past the last scan with an obstacle within the threshold, on two
    scans or more with nothing within it."""
    with_bool = [v for v in verdicts if v.warning_got is not None]
    if not with_bool or with_bool[-1].warning_got is not True:
        return None
    run_from = len(with_bool)
    while run_from > 0 and with_bool[run_from - 1].warning_got is True:
        run_from -= 1
    since = with_bool[run_from].tick
    due = [v.tick for v in verdicts if v.tick >= since and v.expected.warning is True]
    if not due:
        return None  # never rightly True: a wrong threshold, not a warning kept on
    wrong = [
        v.tick
        for v in verdicts
        if v.tick > due[-1] and v.expected.warning is False and v.warning_got is True
    ]
    if len(wrong) < 2:
        return None
    return (
        f"hint: warning True since tick {since} and never cleared (the scans from tick "
        f"{wrong[0]} on had nothing within the threshold)"
    )


def _bounds(verdicts: Sequence[Verdict]) -> tuple[float | None, float | None]:
    """(largest distance it warned at, smallest it published False at)."""
    known = [(v.expected.distance, v.warning_got) for v in verdicts]
    warned_at = [d for d, got in known if got is True and d is not None]
    calm_at = [d for d, got in known if got is False and d is not None]
    return (max(warned_at, default=None), min(calm_at, default=None))


def _other_threshold(verdicts: Sequence[Verdict], threshold: float) -> tuple[float, float] | None:
    """(low, high): the node warns as if its threshold were in (low, high], which holds
    one threshold but not `threshold`; None when warnings did not fail or nothing fits."""
    failed = any(f.startswith(WARNING_FAILURE) for v in verdicts for f in v.failures)
    if not failed:
        return None
    low, high = _bounds(verdicts)  # a threshold T warns below it: low < T <= high
    if low is None or high is None:
        return None  # one-sided: an always-False Bool fits a small threshold, but says little
    if low >= high:
        return None  # no single threshold explains it (an inverted Bool, say)
    if low < threshold <= high:
        return None  # this run's threshold fits: the failures have another cause
    return low, high


def _rounded_crossings(threshold: float, decimals: int) -> list[float]:
    """Where a distance rounded to `decimals` crosses `threshold`: for round(d) < T and
    for round(d) <= T (each only where it differs from T itself)."""
    unit = 10.0**-decimals
    below = math.ceil(threshold / unit - 1e-9) - 1  # largest multiple strictly below
    at_or_below = math.floor(threshold / unit + 1e-9)  # largest multiple at or below
    found = [(m + 0.5) * unit for m in (below, at_or_below)]
    return [c for c in dict.fromkeys(found) if abs(c - threshold) > 1e-9]


def rounding_hint(verdicts: Sequence[Verdict], threshold: float) -> str | None:
    """'the distance is rounded before it is compared', when the node's own threshold
    brackets where a distance rounded to 1 or 2 decimals crosses this run's."""
    bracket = _other_threshold(verdicts, threshold)
    if bracket is None:
        return None
    low, high = bracket
    for decimals in ROUNDED_DECIMALS:
        eps = 1e-6 + 1e-3 * 10.0**-decimals
        for crossing in _rounded_crossings(threshold, decimals):
            if low < crossing + eps and crossing - eps <= high:
                places = "decimal" if decimals == 1 else "decimals"
                return (
                    "hint: it looks like the distance is rounded before it is compared with "
                    f"the threshold: the node warns as if its threshold were between {low:.3f} "
                    f"and {high:.3f} m, and a distance rounded to {decimals} {places} crosses "
                    f"{threshold:g} m at {crossing:.{decimals + 1}f} m"
                    + _own_distance(verdicts, threshold)
                )
    return None


def _own_distance(verdicts: Sequence[Verdict], threshold: float) -> str:
    """'; at tick 7 its own status said 0.460 m, yet its warning was False', if a failed
    tick's Bool disagrees with the distance the node itself reported."""
    for v in verdicts:
        if v.ok or v.claim is None or v.claim.distance is None or v.warning_got is None:
            continue
        if not any(f.startswith(WARNING_FAILURE) for f in v.failures):
            continue
        if (v.claim.distance < threshold) != v.warning_got:
            return (
                f"; at tick {v.tick} its own status said {v.claim.distance:g} m, yet its "
                f"warning was {v.warning_got}"
            )
    return ""


def threshold_hint(verdicts: Sequence[Verdict], threshold: float) -> str | None:
    """'the node warns as if its threshold were ...', when it both warned and did not,
    at distances that fit one other threshold and not this run's; None otherwise."""
    bracket = _other_threshold(verdicts, threshold)
    if bracket is None:
        return None
    low, high = bracket
    return (
        f"hint: the node warns as if its threshold were between {low:.2f} and {high:.2f} m, "
        f"not the {threshold:g} m "
        "the harness passed as its threshold parameter: is the threshold hard-coded?"
    )


# -- the first answer ---------------------------------------------------------------


def first_answer_hint(verdicts: Sequence[Verdict]) -> str | None:
    """Only the first judged tick failed, and it was answered: a first-answer mistake."""
    if len(verdicts) < 2 or verdicts[0].ok or not all(v.ok for v in verdicts[1:]):
        return None
    first = verdicts[0]
    if first.claim is None and first.warning_got is None:
        return None  # not answered: a start-up or link matter, not a wrong answer
    return (
        f"hint: only the node's first answer (tick {first.tick}) was wrong, every later one "
        "was right: does it start from a state its first scan finds unset (a stored result, "
        "a filter started at 0)?"
    )
