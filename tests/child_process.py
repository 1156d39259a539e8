"""Programs under test (a ROS node, a LIDAR driver) running as real child processes.

Their stderr goes to a file, so a failing check can show what they logged;
every wait is bounded, and a test fails (it does not hang) when a process
exits too early or not at all. What a test leaves running is killed.
"""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

import pytest

STOP_TIMEOUT = 5.0


@dataclass
class ChildProcess:
    """A child process, its stderr in a file; `role` ("node", "driver") names it in failures."""

    popen: subprocess.Popen[bytes]
    stderr_path: Path
    role: str = "process"

    def stderr(self) -> str:
        """Everything the process wrote to stderr so far (rclpy logs go there)."""
        return self.stderr_path.read_text(errors="replace")

    def check_alive(self) -> None:
        """Fail at once, with the process's stderr, if it has exited."""
        code = self.popen.poll()
        if code is not None:
            pytest.fail(f"{self.role} exited early with code {code}; stderr:\n{self.stderr()}")

    def wait(self, timeout: float = STOP_TIMEOUT) -> int:
        """Wait (bounded) for the process to exit and return its exit code."""
        try:
            return self.popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{self.role} still running {timeout} s later; stderr:\n{self.stderr()}")

    def stop(self, sig: signal.Signals = signal.SIGTERM, timeout: float = STOP_TIMEOUT) -> int:
        """Send `sig` and return the exit code, failing if it takes over `timeout`."""
        self.popen.send_signal(sig)
        return self.wait(timeout)

    def kill(self) -> None:
        """At teardown: kill the process if it is still running, and reap it."""
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=STOP_TIMEOUT)

    def assert_no_traceback(self) -> None:
        """A clean exit logs, at most; it never dumps a Python traceback."""
        stderr = self.stderr()
        assert "Traceback" not in stderr, stderr


class ChildProcesses:
    """The processes one test starts, their output in `folder`; leaving the `with` kills them."""

    def __init__(self, folder: Path, role: str) -> None:
        self.folder = folder
        self.role = role
        self.started: list[ChildProcess] = []

    def start(
        self,
        argv: Sequence[str],
        *,
        extra_env: dict[str, str] | None = None,
        keep_stdout: bool = False,
    ) -> ChildProcess:
        """Start `argv` unbuffered, with os.environ and `extra_env`; stdout to a file or nowhere."""
        name = self.folder / f"{self.role}{len(self.started)}"
        stderr_path = name.with_suffix(".err")
        env = {**os.environ, "PYTHONUNBUFFERED": "1", **(extra_env or {})}
        stdout_file = (
            name.with_suffix(".out").open("wb") if keep_stdout else nullcontext(subprocess.DEVNULL)
        )
        with stdout_file as stdout, stderr_path.open("wb") as stderr:
            popen = subprocess.Popen(argv, env=env, stdout=stdout, stderr=stderr)
        process = ChildProcess(popen, stderr_path, self.role)
        self.started.append(process)
        return process

    def __enter__(self) -> ChildProcesses:
        return self

    def __exit__(self, *exc_info: object) -> None:
        for process in self.started:
            process.kill()


def alive(pid: int) -> bool:
    """Is process `pid` running (not gone, not a zombie)? From /proc."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "State:\tZ" not in status
