"""A processing function in a forked child process, with a deadline on every call.

A student's ``fn(scan, threshold)`` called in the harness could exit it with 0 (a
false PASS), hang it, crash it or change the scan the oracle judges. Here it runs
in a child forked from the harness (no start-up cost), in its own process group,
SIGINT ignored and SIGKILL on the harness's death; each call is bounded, and what
the function does becomes an ``Outcome`` with a reason. Its output is kept as a
tail for the diagnostics, like a node's."""

from __future__ import annotations

import contextlib
import ctypes
import os
import select
import signal
import sys
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection, Pipe
from pathlib import Path
from typing import Any

from harness.nodes.process import OutputTail, how_it_ended
from harness.nodes.process_group import signal_group, wait_group_gone

__all__ = ["Outcome", "ProcessorChild"]

PR_SET_PDEATHSIG = 1
KILL_WAIT_S = 5.0  # after SIGKILL: only a process stuck in the kernel takes this long
OUTPUT_WAIT_S = 1.0  # for the last of its output once it is gone


@dataclass(frozen=True)
class Outcome:
    """What one call gave: the status and warning, or why there is none."""

    status: str | None = None
    warning: bool | None = None
    seconds: float = 0.0  # how long the function ran, measured in the child
    problem: str | None = None  # raised, returned nonsense, exited, hung, crashed


def _describe_raise(err: BaseException) -> str:
    """`raised ValueError: bad (file.py:12)`, robust to a hostile __str__."""
    try:
        text = str(err)
    except BaseException:  # noqa: BLE001 - its __str__ is the user's code too
        text = "(its message could not be shown)"
    frames = traceback.extract_tb(err.__traceback__)
    where = f" ({Path(frames[-1].filename).name}:{frames[-1].lineno})" if frames else ""
    name = type(err).__name__
    return f"processing function raised {name}{': ' + text if text else ''}{where}"


def _call(fn: Callable[..., Any], scan: Any, threshold: float) -> tuple[Any, ...]:
    """One call in the child: ("ok", status, warning, seconds) or ("problem", reason)."""
    started = time.perf_counter()
    try:
        answer = fn(scan, threshold)
        seconds = time.perf_counter() - started
        if not isinstance(answer, tuple) or len(answer) != 2:
            shown = type(answer).__name__
            return ("problem", f"processing function returned a {shown}, not (status, warning)")
        text, warning = answer
        return ("ok", str(text), None if warning is None else bool(warning), seconds)
    except BaseException as err:  # noqa: BLE001 - SystemExit and KeyboardInterrupt too
        return ("problem", _describe_raise(err))


def _serve(conn: Connection, fn: Callable[..., Any], parent: int) -> None:
    """The child's loop: answer each (scan, threshold) until the harness closes the pipe."""
    os.setpgid(0, 0)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C is the harness's to handle
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:  # the harness died before prctl took effect
        os._exit(1)
    while True:
        try:
            scan, threshold = conn.recv()
        except (EOFError, OSError):
            break
        reply = _call(fn, scan, threshold)
        with contextlib.suppress(BaseException):
            sys.stdout.flush()
            sys.stderr.flush()
        try:
            conn.send(reply)
        except (OSError, ValueError):
            break


class ProcessorChild:
    """One forked child serving `fn`: `call`, then `outcome` within a deadline; `close`."""

    def __init__(self, fn: Callable[..., Any]) -> None:
        self._fn = fn
        self._conn: Connection | None = None
        self._pid: int | None = None
        self._returncode: int | None = None
        self._output: OutputTail | None = None
        self._busy = False

    def start(self) -> None:
        """Fork the child; its stdout and stderr go to a tail the harness keeps."""
        ours, theirs = Pipe()
        out_read, out_write = os.pipe()
        parent = os.getpid()
        with warnings.catch_warnings():  # 3.12: fork with threads running; the child
            warnings.simplefilter("ignore", DeprecationWarning)  # touches none of theirs
            pid = os.fork()
        if pid == 0:  # the child: never returns into the harness's code
            code = 0
            try:
                ours.close()
                os.close(out_read)
                os.dup2(out_write, 1)
                os.dup2(out_write, 2)
                os.close(out_write)
                # print() writes to sys.stdout, which the parent may have replaced
                # (pytest's capture): point both streams at the new fds.
                sys.stdout = open(1, "w", encoding="utf-8", errors="replace", closefd=False)
                sys.stderr = open(2, "w", encoding="utf-8", errors="replace", closefd=False)
                _serve(theirs, self._fn, parent)
            except BaseException:  # noqa: BLE001 - the child must end here, whatever happens
                code = 1
            finally:
                os._exit(code)
        theirs.close()
        os.close(out_write)
        with contextlib.suppress(OSError):  # the child does it too; whoever is first
            os.setpgid(pid, pid)
        self._pid, self._conn = pid, ours
        self._output = OutputTail(out_read, f"processor-{pid}-output")

    def call(self, scan: Any, threshold: float) -> None:
        """Hand the child one scan; if it is gone, `outcome` says how it ended."""
        if self._conn is None:
            return
        try:
            self._conn.send((scan, threshold))
        except (OSError, ValueError):
            return
        self._busy = True

    def outcome(self, timeout: float) -> Outcome:
        """The answer to the last `call` within `timeout` seconds; a child that misses it is
        stopped (one that hung once holds no state anyone can trust)."""
        if self._conn is None or not self._busy:
            return Outcome(problem=self._gone_reason())
        self._busy = False
        try:
            if not self._conn.poll(timeout):
                self.close()
                return Outcome(
                    problem=f"processing function did not return within {timeout:g} s "
                    "(its process was stopped)"
                )
            reply = self._conn.recv()
        except (EOFError, OSError):
            return Outcome(problem=self._gone_reason())
        if reply[0] == "ok":
            _, status, warning, seconds = reply
            return Outcome(status, warning, seconds)
        return Outcome(problem=reply[1])

    def _gone_reason(self) -> str:
        """Why the child cannot answer: how it ended (it is reaped here)."""
        self.close(grace=OUTPUT_WAIT_S)  # it closed its end, or died: let it finish dying
        code = self._returncode
        how = "ended" if code is None else how_it_ended(code)
        return f"processing function ended its process: it {how}{self._last_output()}"

    def _last_output(self) -> str:
        last = self.output_tail(3).replace("\n", " | ")
        return f"; last output: {last}" if last else ""

    def output_tail(self, lines: int = 15) -> str:
        """The last lines the function printed (stdout and stderr together)."""
        return self._output.last_lines(lines) if self._output is not None else ""

    def close(self, *, grace: float = 0.0) -> None:
        """Stop the child and what it started, reap it; idempotent. After `grace` seconds,
        SIGKILL to its group; every wait bounded."""
        if self._conn is not None:
            self._conn.close()
            self._conn = None
        if self._pid is None:
            return
        pid, self._pid = self._pid, None
        if not _wait_exit(pid, grace):
            signal_group(pid, signal.SIGKILL)
            _wait_exit(pid, KILL_WAIT_S)
        with contextlib.suppress(ChildProcessError):
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                self._returncode = os.waitstatus_to_exitcode(status)
        signal_group(pid, signal.SIGKILL)  # anything it left in its group
        wait_group_gone(pid, KILL_WAIT_S)
        if self._output is not None:
            self._output.join(OUTPUT_WAIT_S)


def _wait_exit(pid: int, timeout: float) -> bool:
    """Wait up to `timeout` s for child `pid` to end (not reaping it); True once it has."""
    try:
        fd = os.pidfd_open(pid)
    except OSError:
        return True  # already reaped
    try:
        readable, _, _ = select.select([fd], [], [], timeout)
        return bool(readable)
    finally:
        os.close(fd)
