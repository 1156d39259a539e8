"""`fossbot-hil emulate` as a user runs it: its own process, its output read line by line;
and a LIDAR client run as a user runs one beside it, in a shell given the line it printed."""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

CLIENT = Path(__file__).with_name("lidar_client.py")
CLIENT_TIMEOUT_S = 30.0


class Emulator:
    """`fossbot-hil emulate ...` on a new pty; `port` is the path it printed first, and
    `modem_exports` (on a pty) the shell line of "modem lines: " it printed next."""

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
        self.modem_exports = ""
        if "--port" not in args:
            second = self.wait_for(r"", 10)
            assert second.startswith("modem lines: export "), "\n" + self.text()
            self.modem_exports = second.removeprefix("modem lines: ")

    def client_command(self, *args: str) -> list[str]:
        """``lidar_client.py PORT-less args`` in a POSIX shell that first ran the
        printed "modem lines" line: how a user runs a client in a second shell."""
        assert self.modem_exports, "no modem lines: emulate was given --port"
        script = f'{self.modem_exports}; exec "$@"'
        return ["sh", "-c", script, "sh", sys.executable, str(CLIENT), *args]

    def start_client(self, *args: str, env: dict[str, str] | None = None) -> subprocess.Popen:
        """`lidar_client.py LIBRARY <port> args...` started beside the emulator."""
        library, *rest = args
        return subprocess.Popen(
            self.client_command(library, self.port, *rest),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, **(env or {})},
        )

    def run_client(
        self, *args: str, env: dict[str, str] | None = None, timeout: float = CLIENT_TIMEOUT_S
    ) -> dict[str, Any]:
        """`start_client`, waited for (at most `timeout` s): the JSON it printed."""
        client = self.start_client(*args, env=env)
        try:
            out, err = client.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            client.kill()
            out, err = client.communicate(timeout=10)
            raise AssertionError(f"client still running after {timeout} s:\n{err}") from None
        assert client.returncode == 0, f"client exit {client.returncode}:\n{err}\n" + self.text()
        return json.loads(out)

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
        """End it if still running: SIGTERM (a normal end: it removes its pty's
        modem-line socket), then SIGKILL after 10 s."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=10)
