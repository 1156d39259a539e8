"""The user's cache folder for what fossbot-hil keeps between commands (pure).

``$FOSSBOT_HIL_CACHE_DIR`` when set (a CI job's or a test suite's own),
else ``$XDG_CACHE_HOME/fossbot-hil`` (``~/.cache`` when unset or not
absolute), as the XDG base directory rules say. Each user of it takes a
folder of its own inside: ``last-run`` (run's verdicts), ``audit`` (audits
of suites).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

__all__ = ["CACHE_VARIABLE", "cache_root"]

CACHE_VARIABLE = "FOSSBOT_HIL_CACHE_DIR"


def cache_root(env: Mapping[str, str] | None = None) -> Path:
    """The folder every fossbot-hil cache lives under."""
    env = os.environ if env is None else env
    own = env.get(CACHE_VARIABLE)
    if own:
        return Path(own)
    base = env.get("XDG_CACHE_HOME", "")
    if not os.path.isabs(base):  # unset, or relative (which the XDG rules say to ignore)
        base = os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fossbot-hil"
