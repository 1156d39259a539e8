"""`fossbot-hil ports`: what each adapter likely is, and whether this user may open it.

Permissions are checked by the kernel on a real tty (a pty slave given the
owner, group and mode a USB-UART gets), from a child process that has become
an ordinary user, as a student on a lab PC is.
"""

from __future__ import annotations

import grp
import os
import pwd
import select
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator

import pytest

from harness.serial_line.adapters import access_problem, likely_adapter

pytestmark = pytest.mark.timeout(30)

CHILD_WAIT_S = 10.0


@pytest.fixture
def tty_path() -> Iterator[str]:
    """A real tty device (a pty slave) whose owner, group and mode the test sets."""
    master, slave = os.openpty()
    try:
        yield os.ttyname(slave)
    finally:
        os.close(slave)
        os.close(master)


def as_user(uid: int, gid: int, check: Callable[[], str | None]) -> str | None:
    """`check()` in a forked child running as uid/gid with no supplementary groups."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: drop root, answer, leave at once
        try:
            os.close(read_end)
            os.setgroups([])
            os.setgid(gid)
            os.setuid(uid)
            answer = check()
            os.write(write_end, ("-" if answer is None else "+" + answer).encode())
        finally:
            os._exit(0)
    os.close(write_end)
    try:
        ready = select.select([read_end], [], [], CHILD_WAIT_S)[0]
        text = os.read(read_end, 4096).decode() if ready else ""
    finally:
        os.close(read_end)
        if not ready:
            os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    assert text, f"the child gave no answer within {CHILD_WAIT_S:g} s"
    return None if text == "-" else text[1:]


needs_root = pytest.mark.skipif(
    os.geteuid() != 0, reason="setting a tty's owner and becoming another user needs root"
)


@needs_root
def test_a_user_outside_the_ports_group_is_told_to_join_it(tty_path: str) -> None:
    nobody = pwd.getpwnam("nobody")
    dialout = grp.getgrnam("dialout").gr_gid
    os.chown(tty_path, 0, dialout)
    os.chmod(tty_path, 0o660)
    problem = as_user(nobody.pw_uid, nobody.pw_gid, lambda: access_problem(tty_path))
    assert problem is not None
    assert problem.startswith("not in group dialout: `sudo usermod -aG dialout $USER`")
    assert "udev rule" in problem


@needs_root
def test_a_group_joined_after_login_asks_for_a_new_session(tty_path: str) -> None:
    """The user's entry names the group, but this process is not in it (an old login)."""
    nobody = pwd.getpwnam("nobody")
    os.chown(tty_path, 0, nobody.pw_gid)
    os.chmod(tty_path, 0o660)
    other = grp.getgrnam("dialout").gr_gid
    problem = as_user(nobody.pw_uid, other, lambda: access_problem(tty_path))
    group = grp.getgrgid(nobody.pw_gid).gr_name
    assert problem == (
        f"you are in group {group}, this login session is not yet: "
        f"log out and in (or run `newgrp {group}`)"
    )


@needs_root
def test_a_port_no_group_may_open_asks_for_a_udev_rule(tty_path: str) -> None:
    """Mode 0600 root:root: joining a group would not help; the fix is the rule's mode."""
    nobody = pwd.getpwnam("nobody")
    os.chown(tty_path, 0, 0)
    os.chmod(tty_path, 0o600)
    problem = as_user(nobody.pw_uid, nobody.pw_gid, lambda: access_problem(tty_path))
    assert problem is not None and problem.startswith("mode 0600, group root: no group may")
    assert 'MODE="0660"' in problem and "usermod" not in problem


@needs_root
def test_a_port_this_user_may_open_has_no_problem(tty_path: str) -> None:
    nobody = pwd.getpwnam("nobody")
    os.chmod(tty_path, 0o666)
    assert as_user(nobody.pw_uid, nobody.pw_gid, lambda: access_problem(tty_path)) is None


def test_a_missing_port_cannot_be_seen() -> None:
    assert access_problem("/dev/ttyUSB_no_such_adapter") == (
        "cannot see it: No such file or directory"
    )


@pytest.mark.parametrize(
    ("device", "vid_pid", "likely"),
    [
        ("/dev/ttyUSB0", "10C4:EA60", "Silicon Labs CP210x (the RPLIDAR A1's own adapter"),
        ("/dev/ttyUSB1", "1a86:7523", "WCH CH340 USB-UART"),
        ("/dev/ttyUSB2", "0403:6001", "FTDI FT232R USB-UART"),
        ("/dev/ttyUSB3", "0403:FFFF", "FTDI adapter"),
        ("/dev/ttyACM0", "1234:5678", "USB device (unknown chip)"),
        ("/dev/ttyAMA0", None, "built-in UART, not USB"),
        ("/dev/ttyS0", None, "built-in UART, not USB"),
        ("/dev/rfcomm0", None, "not a USB adapter"),
    ],
)
def test_likely_adapter_from_the_usb_id_or_the_name(
    device: str, vid_pid: str | None, likely: str
) -> None:
    assert likely_adapter(device, vid_pid).startswith(likely)


def test_ports_prints_a_header_and_per_port_kind_and_access() -> None:
    """The command as a user runs it: a header, then one row per adapter with a verdict."""
    from harness.serial_line.ports import list_serial_ports

    done = subprocess.run(
        [sys.executable, "-m", "harness.cli", "ports"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    ports = list_serial_ports()
    if not ports:
        assert lines == ["no serial adapters found (plug in the USB-UART, then try again)"]
        return
    assert lines[0].split() == ["PORT", "USB", "ID", "LIKELY", "MAY", "OPEN"]
    rows = lines[1 : 1 + len(ports)]
    for port, row in zip(ports, rows, strict=True):
        assert row.startswith(port.device), row
        assert likely_adapter(port.device, port.vid_pid) in row
        assert row.endswith(" yes") or " no: " in row, row
    if any(port.vid_pid is None for port in ports):
        assert any(line.startswith("USB ID -: not a USB device") for line in lines)
