"""How long this command has been running: since the harness was first imported.

Not since the process started: a shell may exec the command in a process it
started long before (``bash -c "pip install ... && fossbot-hil run"`` does),
and the process's start time then counts the install. The interpreter's own
start before the first import (about 0.05 s) is not counted.
"""

from __future__ import annotations

import time

import harness


def command_seconds() -> float:
    """Seconds since the harness package was first imported in this process."""
    return time.monotonic() - harness.IMPORTED_AT
