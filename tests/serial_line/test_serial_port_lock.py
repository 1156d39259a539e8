"""Port lock: runs on one serial port take turns across processes; the device opens exclusively."""

from __future__ import annotations

import fcntl
import os
import select
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.serial_line.port_lock import hold_port
from harness.serial_line.ports import SerialPort

pytestmark = pytest.mark.timeout(30)

HOLDER = """
import sys
from harness.serial_line.port_lock import hold_port
lock = hold_port(sys.argv[1], float(sys.argv[2]))
print("held", flush=True)
sys.stdin.readline()  # hold until told
lock.release()
"""


@pytest.fixture
def tty() -> Iterator[str]:
    """A pty slave path: a serial device as a USB-UART's would be."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    yield path
    os.close(master)


class Holder:
    """Another process holding the port until `let_go()`."""

    def __init__(self, device: str, wait: float = 0.0) -> None:
        self.popen = subprocess.Popen(
            [sys.executable, "-c", HOLDER, device, str(wait)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )

    def wait_held(self, timeout: float = 10.0) -> None:
        assert self.popen.stdout is not None
        ready = select.select([self.popen.stdout], [], [], timeout)[0]
        assert ready, "the holder never took the port"
        line = self.popen.stdout.readline()
        assert line == "held\n", line + (self.popen.stderr.read() if self.popen.stderr else "")

    def let_go(self) -> int:
        assert self.popen.stdin is not None
        self.popen.stdin.write("\n")
        self.popen.stdin.flush()
        return self.popen.wait(timeout=10)

    def kill(self) -> None:
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=10)


@pytest.fixture
def holders() -> Iterator[list[Holder]]:
    started: list[Holder] = []
    yield started
    for holder in started:
        holder.kill()


def test_a_held_port_makes_others_wait_then_names_the_holder(tty: str, holders) -> None:
    """A bounded wait, then one line naming who has the port."""
    holder = Holder(tty)
    holders.append(holder)
    holder.wait_held()
    started = time.monotonic()
    with pytest.raises(ConfigError) as err:
        hold_port(tty, 0.3, label=f"--port {tty}")
    assert time.monotonic() - started >= 0.3
    message = str(err.value)
    assert message.startswith(f"--port {tty}: in use by pid {holder.popen.pid} (-c")
    assert message.endswith("waited 0.3 s for it to finish") and "\n" not in message


def test_the_next_run_gets_the_port_when_the_holder_is_done(tty: str, holders) -> None:
    """Taking turns: a waiting run proceeds as soon as the holder lets go."""
    first = Holder(tty)
    holders.append(first)
    first.wait_held()
    second = Holder(tty, wait=20.0)  # queues behind the first
    holders.append(second)
    assert not select.select([second.popen.stdout], [], [], 0.5)[0]  # still waiting
    assert first.let_go() == 0
    second.wait_held()
    assert second.let_go() == 0


def test_a_dead_holder_frees_the_port(tty: str, holders) -> None:
    """The kernel drops a crashed run's lock: no stale lock files to clean up."""
    holder = Holder(tty)
    holders.append(holder)
    holder.wait_held()
    holder.kill()
    with hold_port(tty, 0.0):
        pass


def test_a_symlink_and_its_device_are_one_port(tty: str, tmp_path: Path, holders) -> None:
    """/dev/serial/by-id/... and /dev/ttyUSB0 name the same adapter."""
    link = tmp_path / "usb-Silicon_Labs_CP2102-if00-port0"
    link.symlink_to(tty)
    holder = Holder(str(link))
    holders.append(holder)
    holder.wait_held()
    with pytest.raises(ConfigError, match="in use by pid"):
        hold_port(tty, 0.0)


def test_the_lock_is_reentrant_within_a_process(tty: str, holders) -> None:
    """The plugin holds the port for a test; the link inside takes it again."""
    outer = hold_port(tty, 0.0)
    inner = hold_port(tty, 0.0)
    inner.release()
    holder = Holder(tty, wait=20.0)
    holders.append(holder)
    assert not select.select([holder.popen.stdout], [], [], 0.3)[0]  # still held by `outer`
    outer.release()
    outer.release()  # twice is harmless
    holder.wait_held()


def test_serial_port_holds_the_lock_until_closed(tty: str, holders) -> None:
    """SerialPort takes the port's turn; close() gives it back."""
    port = SerialPort(tty, lock_wait=0.0)
    try:
        holder = Holder(tty, wait=20.0)
        holders.append(holder)
        assert not select.select([holder.popen.stdout], [], [], 0.3)[0]
    finally:
        port.close()
    holder.wait_held()


def test_serial_port_waits_for_a_run_on_its_port(tty: str, holders) -> None:
    """A second run on the same adapter fails after the wait with the holder named."""
    holder = Holder(tty)
    holders.append(holder)
    holder.wait_held()
    with pytest.raises(ConfigError, match=rf"^--port {tty}: in use by pid {holder.popen.pid}"):
        SerialPort(tty, lock_wait=0.2)


def test_serial_port_opens_the_device_exclusively(tty: str) -> None:
    """A program outside the harness that holds the device exclusively keeps it."""
    other = os.open(tty, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)  # as pyserial's exclusive=True does
        with pytest.raises(ConfigError) as err:
            SerialPort(tty, lock_wait=0.0)
        assert str(err.value) == f"--port {tty}: already open elsewhere, with an exclusive lock"
    finally:
        os.close(other)
    with hold_port(tty, 0.0):  # the refused open gave its turn back
        pass
    port = SerialPort(tty, lock_wait=0.0)
    try:
        probe = os.open(tty, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            with pytest.raises(BlockingIOError):  # and ours is exclusive too
                fcntl.flock(probe, fcntl.LOCK_EX | fcntl.LOCK_NB)
        finally:
            os.close(probe)
    finally:
        port.close()
