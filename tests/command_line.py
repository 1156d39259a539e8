"""Running `fossbot-hil` for real, in its own process, as a user would."""

from __future__ import annotations

import subprocess
import sys

COMMAND = [sys.executable, "-m", "harness.cli"]


def fossbot_hil(*args: str, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    """Run the command to completion (bounded) and capture its output."""
    return subprocess.run([*COMMAND, *args], capture_output=True, text=True, timeout=timeout)
