"""The board at the far end of a pty null-modem cable, for the `--port` tests.

The harness opens one end of the cable as it would a USB-UART; the board's
processes (its LIDAR driver, its nodes) run on the other end in their own
ROS domain, started once the harness holds its end open, as a real board's
driver must be: an A1 answers only requests, and whatever a driver sent to
an unattended line is lost.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path

import pytest
from pty_clients import NullModem

from harness.ros.domain import reserve_domain
from harness.serial_line.modem_lines import client_environment

OPEN_WAIT_S = 60.0
REFERENCE_NODE = [sys.executable, "-m", "harness.reference.lidar_node"]


def bundled_driver(port: str) -> list[str]:
    """The bundled board driver on `port`, with its defaults (the v2 bridge's mapping)."""
    return [
        *(sys.executable, "-m", "harness.board_driver.rplidar_node", "--ros-args"),
        *("-p", f"port:={port}", "-p", "timeout:=30.0"),
    ]


def holds_open(pid: int, path: str) -> bool:
    """Whether process `pid` has `path` open (from /proc)."""
    try:
        return any(os.path.realpath(fd) == path for fd in Path(f"/proc/{pid}/fd").iterdir())
    except OSError:
        return False


class FarEnd:
    """The board's end of the cable: its processes, in its domain, logged to files."""

    def __init__(self, cable: NullModem, domain_id: int, folder: Path) -> None:
        self.cable, self.domain_id, self.folder = cable, domain_id, folder
        self.processes: list[subprocess.Popen[bytes]] = []

    def start(
        self,
        harness: subprocess.Popen[str],
        *argvs: list[str],
        env_for: Callable[[list[str], Mapping[str, str]], Mapping[str, str]] | None = None,
    ) -> None:
        """Once `harness` holds its end open, start each of `argvs` (`env_for` may give
        one its own environment)."""
        deadline = time.monotonic() + OPEN_WAIT_S
        while not holds_open(harness.pid, self.cable.harness_end):
            assert harness.poll() is None, "the harness exited before opening the port"
            assert time.monotonic() < deadline, "the harness never opened the port"
            time.sleep(0.05)  # polling an observable condition, bounded
        env = {
            **os.environ,
            "ROS_DOMAIN_ID": str(self.domain_id),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        }
        # A pty has no modem lines: the documented environment makes the board's
        # pyserial calls on it succeed (they go nowhere: --port cannot carry them).
        env.update(client_environment(self.cable.board_end, None, env))
        for index, argv in enumerate(argvs):
            own = env_for(argv, env) if env_for is not None else env
            with open(self.folder / f"board{index}.log", "wb") as log:
                self.processes.append(
                    subprocess.Popen(argv, env=dict(own), stdout=log, stderr=subprocess.STDOUT)
                )

    def logs(self) -> str:
        return "\n".join(p.read_text(errors="replace") for p in self.folder.glob("board*.log"))

    def stop(self) -> None:
        for process in self.processes:
            process.terminate()
        for process in self.processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=5)


@pytest.fixture
def far_end(tmp_path: Path) -> Iterator[FarEnd]:
    cable = NullModem()
    reservation = reserve_domain()
    board = FarEnd(cable, reservation.domain_id, tmp_path)
    try:
        yield board
    finally:
        board.stop()
        cable.cut()
        reservation.release()
