"""`fossbot-hil run --watch` as a real child process, its stdout read line by line.

The output is a pipe (not a terminal), so the command writes plain lines,
each flushed when it happens; a thread reads them into a queue, and every
wait for a line is bounded: a test fails with what did arrive, not hangs.
"""

from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import pytest

STUDENT = Path(__file__).resolve().parents[1] / "ros" / "student_node.py"
VARIANT_LINE = '    variant = sys.argv[1] if len(sys.argv) > 1 else "correct"'
COMMAND = [sys.executable, "-m", "harness.cli", "run"]
LINE_TIMEOUT = 60.0  # one run of a few scenarios, a node start, a colcon build on a slow CI
STOP_TIMEOUT = 20.0


def descendants(pid: int) -> set[int]:
    """Every process below `pid` (children, theirs, ...), from /proc."""
    found: set[int] = set()
    todo = [pid]
    while todo:
        parent = todo.pop()
        tasks = Path(f"/proc/{parent}/task")
        try:
            names = os.listdir(tasks)
        except OSError:  # it exited while we looked
            continue
        for name in names:
            try:
                children = {int(c) for c in (tasks / name / "children").read_text().split()}
            except OSError:
                continue
            todo += sorted(children - found)
            found |= children
    return found


class WatchProcess:
    """`fossbot-hil run --watch ARGS` in `cwd`, with `env` added to os.environ."""

    def __init__(self, args: Sequence[str], *, cwd: Path, env: dict[str, str]) -> None:
        self.stderr_path = cwd / "watch.err"
        with self.stderr_path.open("wb") as stderr:
            self.popen = subprocess.Popen(
                [*COMMAND, *args, "--watch"],
                cwd=cwd,
                env={**os.environ, "PYTHONUNBUFFERED": "1", **env},
                stdout=subprocess.PIPE,
                stderr=stderr,
                text=True,
            )
        self.lines: list[str] = []  # every line read so far
        self._read = 0  # lines already handed out by `expect`
        self._queue: queue.Queue[str | None] = queue.Queue()
        self.seen: set[int] = set()  # every process seen below the command
        threading.Thread(target=self._reader, daemon=True).start()

    def _reader(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self._queue.put(line.rstrip("\n"))
        self._queue.put(None)

    def stderr(self) -> str:
        return self.stderr_path.read_text(errors="replace")

    def _failure(self, what: str) -> str:
        shown = "\n".join(self.lines[-40:])
        return f"{what}; output so far:\n{shown}\nstderr:\n{self.stderr()}"

    def expect(self, pattern: str, timeout: float = LINE_TIMEOUT) -> list[str]:
        """The lines up to and including the next one matching `pattern` (a regex)."""
        deadline = time.monotonic() + timeout
        while True:
            for index in range(self._read, len(self.lines)):
                if re.search(pattern, self.lines[index]):
                    got = self.lines[self._read : index + 1]
                    self._read = index + 1
                    return got
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                pytest.fail(self._failure(f"no line matching {pattern!r} within {timeout} s"))
            try:
                line = self._queue.get(timeout=remaining)
            except queue.Empty:
                continue
            if line is None:
                pytest.fail(self._failure(f"the command ended before {pattern!r}"))
            self.lines.append(line)
            self.seen |= descendants(self.popen.pid)

    def interrupt(self, sig: int = signal.SIGINT) -> int:
        """Send `sig` (Ctrl-C by default) and wait, bounded, for the exit code."""
        self.seen |= descendants(self.popen.pid)
        self.popen.send_signal(sig)
        try:
            code = self.popen.wait(timeout=STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            pytest.fail(self._failure(f"still running {STOP_TIMEOUT} s after {sig}"))
        deadline = time.monotonic() + STOP_TIMEOUT
        while True:  # what it wrote as it stopped, up to the end of its output
            try:
                line = self._queue.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            self.lines.append(line)
        return code

    def kill(self) -> None:
        """At teardown: kill the command if it still runs, and reap it."""
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=STOP_TIMEOUT)


def student_variant(variant: str, *, pids: Path | None = None) -> str:
    """tests/ros/student_node.py with `variant` written into it (a student's one file),
    and (with `pids`) a line that appends each node's pid to that file."""
    text = STUDENT.read_text()
    assert VARIANT_LINE in text
    text = text.replace(VARIANT_LINE, f'    variant = "{variant}"')
    if pids is not None:
        record = f'    open({str(pids)!r}, "a").write(f"{{__import__(\'os\').getpid()}}\\n")\n'
        text = text.replace(
            "    rclpy.init(args=sys.argv)\n", record + "    rclpy.init(args=sys.argv)\n"
        )
    return text


def save(path: Path, text: str) -> None:
    """Save a file as an editor does: the new text under the same name."""
    path.write_text(text)


def save_by_rename(path: Path, text: str) -> None:
    """Save as editors that write a new file and rename it over the old one: a reader
    never sees half a file. For saves while a run may be loading the file."""
    new = path.with_name(f".{path.name}.new")
    new.write_text(text)
    os.replace(new, path)


def verdict_lines(lines: Sequence[str]) -> list[str]:
    """The scenario names of the PASS / FAIL / ERROR lines, in order."""
    return [
        line.split()[1] for line in lines if line.split()[:1] in (["PASS"], ["FAIL"], ["ERROR"])
    ]
