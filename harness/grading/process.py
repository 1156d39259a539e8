"""A child process bounded in time and in output, logged to a file, and killable.

Student code runs in these (colcon runs their setup.py; the worker runs
their node), so none of it may hang the grader, fill the disk, or outlive
it. Each child gets its own process group, so stopping it stops whatever it
started; it writes to a file, never a pipe, so it can never block on us.

Run as ``python -m harness.grading.process MAX_FILE_BYTES CMD ARGS...``,
this module asks Linux to SIGTERM it when the grader's thread that started
it dies, caps the size of any one file it and its children write (a node
printing forever into its log gets EFBIG, not the whole disk), then execs
CMD: even a SIGKILLed grader leaves no build or run behind. (Doing this in
the parent with ``preexec_fn`` is unsafe with threads.)
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from harness.nodes.process_group import signal_group, wait_group_gone

__all__ = ["StopFlag", "Finished", "guarded", "run_bounded", "stop_child"]

MAX_FILE_BYTES = 128 * 1024 * 1024  # any one file a student's build or node writes
# How often a running child's log size and the cancel flag are looked at: a child
# flooding its log writes hundreds of MB a second, so a cheap stat() often keeps the
# overshoot small.
POLL_S = 0.02
TERM_GRACE_S = 15.0  # after SIGTERM: a worker stops its node (up to 9 s) and writes results
KILL_WAIT_S = 5.0
PR_SET_PDEATHSIG = 1


class StopFlag(Protocol):
    """What asks a child to stop: a threading.Event, or a flag set across a cluster."""

    def is_set(self) -> bool: ...


@dataclass(frozen=True)
class Finished:
    """How a bounded child ended. `returncode` is None only if it could not be started."""

    returncode: int | None
    wall_s: float
    timed_out: bool = False
    flooded: bool = False  # wrote more than the log limit
    cancelled: bool = False
    start_error: str | None = None

    @property
    def ok(self) -> bool:
        return self.returncode == 0 and not (self.timed_out or self.flooded or self.cancelled)


def stop_child(popen: subprocess.Popen[Any]) -> None:
    """SIGTERM the group, then SIGKILL it after a bounded wait; reap the child."""
    for sig, grace in ((signal.SIGTERM, TERM_GRACE_S), (signal.SIGKILL, KILL_WAIT_S)):
        if popen.poll() is not None:
            break
        signal_group(popen.pid, sig)
        try:
            popen.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            continue
    signal_group(popen.pid, signal.SIGKILL)  # anything the child left in its group
    try:
        popen.wait(timeout=KILL_WAIT_S)
    except subprocess.TimeoutExpired:  # unkillable (D state): give up on it, do not hang
        pass
    wait_group_gone(popen.pid, KILL_WAIT_S)


def guarded(argv: Sequence[str], max_file_bytes: int = MAX_FILE_BYTES) -> list[str]:
    """`argv` started through this module: it dies with the thread that started it, and
    no file it writes grows past `max_file_bytes`."""
    return [sys.executable, "-m", "harness.grading.process", str(max_file_bytes), *argv]


def run_bounded(
    argv: Sequence[str],
    *,
    log: Path,
    timeout: float,
    max_log_bytes: int,
    cwd: Path | None = None,
    env: dict[str, str] | None = None,
    cancel: StopFlag | None = None,
    max_file_bytes: int = MAX_FILE_BYTES,
) -> Finished:
    """Run `argv` with stdout and stderr in `log`; stop it on timeout, flood or cancel."""
    started = time.monotonic()
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "ab") as out:
        try:
            popen = subprocess.Popen(
                guarded(argv, max_file_bytes),
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                cwd=cwd,
                env={**os.environ, **(env or {}), "PYTHONUNBUFFERED": "1"},
                start_new_session=True,
            )
        except OSError as err:
            return Finished(None, 0.0, start_error=f"cannot start {argv[0]}: {err.strerror}")
    timed_out = flooded = cancelled = False
    deadline = started + timeout
    try:
        while True:
            try:
                popen.wait(timeout=max(0.0, min(POLL_S, deadline - time.monotonic())))
                break
            except subprocess.TimeoutExpired:
                pass
            if time.monotonic() >= deadline:
                timed_out = True
            elif log.stat().st_size > max_log_bytes:
                flooded = True
            elif cancel is not None and cancel.is_set():
                cancelled = True
            if timed_out or flooded or cancelled:
                stop_child(popen)
                break
    except BaseException:
        stop_child(popen)
        raise
    return Finished(
        popen.returncode,
        time.monotonic() - started,
        timed_out=timed_out,
        flooded=flooded,
        cancelled=cancelled,
    )


def _exec_guarded(max_file_bytes: int, argv: list[str]) -> None:
    """Die with the parent (SIGTERM), cap file sizes, then become `argv`."""
    import ctypes
    import resource

    parent = os.getppid()
    hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]
    cap = max_file_bytes if hard == resource.RLIM_INFINITY else min(hard, max_file_bytes)
    resource.setrlimit(resource.RLIMIT_FSIZE, (cap, cap))
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        sys.exit(1)
    try:
        os.execvp(argv[0], argv)
    except OSError as err:
        print(f"cannot run {argv[0]}: {err.strerror}", file=sys.stderr)
        sys.exit(127)


if __name__ == "__main__":
    if len(sys.argv) < 3 or not sys.argv[1].isdigit():
        sys.exit("usage: python -m harness.grading.process MAX_FILE_BYTES CMD [ARGS...]")
    _exec_guarded(int(sys.argv[1]), sys.argv[2:])
