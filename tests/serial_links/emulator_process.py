"""`fossbot-hil emulate` as a user runs it: its own process, its output read line by line."""

from __future__ import annotations

import queue
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path


class Emulator:
    """`fossbot-hil emulate ...` on a new pty; `port` is the path it printed first."""

    def __init__(self, *args: str, cwd: Path | None = None) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "harness.cli", "emulate", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=cwd,
        )
        self.lines: list[str] = []
        self._queue: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        first = self.wait_for(r"^port: ", 30)
        self.port = first.removeprefix("port: ").strip()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._queue.put(line.rstrip("\n"))
        self._queue.put(None)

    def wait_for(self, pattern: str, timeout: float) -> str:
        """The first line (from now on) matching `pattern`; fails after `timeout` s."""
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            assert left > 0, f"no line matching {pattern!r} in {timeout} s:\n" + self.text()
            try:
                line = self._queue.get(timeout=left)
            except queue.Empty:
                continue
            assert line is not None, f"emulate ended before {pattern!r}:\n" + self.text()
            self.lines.append(line)
            if re.search(pattern, line):
                return line

    def finish(self, sig: int | None = signal.SIGINT, timeout: float = 30) -> int:
        """Send `sig` (None: let the scenario end), wait for the exit; the exit code."""
        if sig is not None:
            self.process.send_signal(sig)
        rc = self.process.wait(timeout=timeout)
        while (line := self._queue.get(timeout=5)) is not None:
            self.lines.append(line)
        return rc

    def text(self) -> str:
        return "\n".join(self.lines)

    def summary_field(self, name: str) -> str:
        """The text after "  name: " in the closing summary."""
        found = [line for line in self.lines if line.startswith(f"  {name}: ")]
        assert found, f"no '{name}:' line in:\n" + self.text()
        return found[-1].removeprefix(f"  {name}: ")

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(timeout=10)
