"""Running `fossbot-hil` for real, in its own process, as a user would."""

from __future__ import annotations

import subprocess
import sys

COMMAND = [sys.executable, "-m", "harness.cli"]
# Each status's deadline in a run in real time (a board's own software, a physical port): a
# loaded CI machine has held a node's answer back 3 s, and latency is not what those tests
# show (the device living for the run, repeats and loss handled).
REAL_TIME_DEADLINE = ("--timeout", "5")


def fossbot_hil(*args: str, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    """Run the command to completion (bounded) and capture its output."""
    return subprocess.run([*COMMAND, *args], capture_output=True, text=True, timeout=timeout)
