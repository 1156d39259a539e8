"""How many examples the slowest property tests draw.

Each of their examples runs a whole scenario, command or report, so they
set the suite's length. A plain run draws the counts the tests name (a new
sample every run); ``FOSSBOT_HIL_PROPERTY_DEPTH=4 pytest tests/robustness``
draws four times as many, for a deeper search before a release.
"""

from __future__ import annotations

import os

_SETTING = os.environ.get("FOSSBOT_HIL_PROPERTY_DEPTH", "1")
try:
    DEPTH = float(_SETTING)
except ValueError:
    raise SystemExit(f"FOSSBOT_HIL_PROPERTY_DEPTH must be a number, got {_SETTING!r}") from None


def examples(count: int) -> int:
    """`count` examples, scaled by FOSSBOT_HIL_PROPERTY_DEPTH (at least 1)."""
    return max(1, round(count * DEPTH))
