"""``colcon build`` of the package under test before a re-run, bounded in time and output.

As the student would run it, with the workspace's own install layout
(colcon refuses to switch), stopped after `BUILD_TIMEOUT_S` or on Ctrl-C;
a failed build shows the line that says why (as `grade` finds it).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from pathlib import Path

from harness.grading.build import EVENT_HANDLERS, build_error, colcon_executable
from harness.grading.process import run_bounded
from harness.watch.sources import Build

__all__ = ["BUILD_TIMEOUT_S", "BuildOutcome", "build_log", "rebuild"]

BUILD_TIMEOUT_S = 300.0
MAX_LOG_BYTES = 20 * 1024 * 1024
TAIL_LINES = 12
# A Python error line (as grading.build reads them), and colcon's report that setup.py failed.
ERROR_LINE = re.compile(r"^(?:[A-Za-z_][\w.]*\.)?[A-Z]\w*(?:Error|Exception)\b")
COLCON_WRAPPER = ("subprocess.CalledProcessError", "CalledProcessError")


@dataclass(frozen=True)
class BuildOutcome:
    """A rebuild: how long it took, and (when it failed) why and the log's last lines."""

    seconds: float
    log: Path
    error: str | None = None
    tail: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.error is None


def build_log(build: Build) -> Path:
    """Where the rebuild's output goes: colcon's own log folder of the workspace."""
    return build.workspace / "log" / "fossbot-hil-watch.log"


def _tail(text: str, lines: int = TAIL_LINES) -> tuple[str, ...]:
    """The log's lines that show why: up to the first error of the student's code (colcon's
    own traceback around it says only that setup.py failed), else the log's last lines."""
    kept = [line.rstrip() for line in text.splitlines() if line.strip()]
    for index, line in enumerate(kept):
        if ERROR_LINE.match(line) and not line.startswith(COLCON_WRAPPER):
            return tuple(kept[max(0, index - lines + 1) : index + 1])
    return tuple(kept[-lines:])


def rebuild(build: Build, *, timeout: float = BUILD_TIMEOUT_S) -> BuildOutcome:
    """Build the package; ConfigError when colcon is not installed."""
    log = build_log(build)
    log.unlink(missing_ok=True)
    command = build.command(colcon_executable(), ["--event-handlers", *EVENT_HANDLERS])
    started = time.monotonic()
    finished = run_bounded(
        command, log=log, timeout=timeout, max_log_bytes=MAX_LOG_BYTES, cwd=build.workspace
    )
    seconds = time.monotonic() - started
    if finished.ok:
        return BuildOutcome(seconds, log)
    error: str | None = None
    if finished.start_error:
        error = finished.start_error
    elif finished.timed_out:
        error = f"the build took longer than {timeout:g} s (stopped)"
    elif finished.flooded:
        error = f"the build wrote more than {MAX_LOG_BYTES >> 20} MB of output (stopped)"
    text = log.read_text(encoding="utf-8", errors="replace") if log.is_file() else ""
    if error is None:
        error = build_error(text, hide=(build.workspace,))
    return BuildOutcome(seconds, log, error, _tail(text))
