"""Hints drawn from a whole run, for mistakes no single tick reveals (pure).

A node that keeps its own threshold (``self.threshold = 0.5``) instead of
the ``threshold`` parameter fails one tick as "expected warning False; got
True", which says what but not why. Across the run, the distances at which
it warned and did not warn bracket the threshold it really uses; when that
bracket excludes the threshold the harness passed, say so.
"""

from __future__ import annotations

from collections.abc import Sequence

from harness.judge.oracle import Verdict

WARNING_FAILURE = "expected warning"


def _bounds(verdicts: Sequence[Verdict]) -> tuple[float | None, float | None]:
    """(largest distance it warned at, smallest it published False at)."""
    warned = [v.expected.distance for v in verdicts if v.warning_got is True]
    calm = [v.expected.distance for v in verdicts if v.warning_got is False]
    warned_at = [d for d in warned if d is not None]
    calm_at = [d for d in calm if d is not None]
    return (max(warned_at) if warned_at else None, min(calm_at) if calm_at else None)


def threshold_hint(verdicts: Sequence[Verdict], threshold: float) -> str | None:
    """'the node warns as if its threshold were ...', when it both warned and did not,
    at distances that fit one other threshold and not this run's; None otherwise."""
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
    return (
        f"hint: the node warns as if its threshold were between {low:.2f} and {high:.2f} m, "
        f"not the {threshold:g} m "
        "the harness passed as its threshold parameter: is the threshold hard-coded?"
    )
