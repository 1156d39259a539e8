"""Checks both LIDAR drivers must pass alike, whatever their device's protocol.

Each process test module starts its own device on the pty (a scripted
RPLIDAR, an LD packet stream) and hands the rest of the check to these.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from child_process import ChildProcess
from driver_wire import Pty


def check_missing_port_exits_2_with_one_line(
    start_driver: Callable[..., ChildProcess], module: str
) -> None:
    """No such device: exit 2 and exactly one log line, naming the port."""
    driver = start_driver(module, "-p", "port:=/dev/fossbot-hil-no-such-tty")
    assert driver.wait() == 2
    lines = [line for line in driver.stderr().splitlines() if line.strip()]
    assert len(lines) == 1, lines
    assert "cannot open /dev/fossbot-hil-no-such-tty" in lines[0]


def check_port_vanishing_exits_1_promptly(
    pty: Pty, start_driver: Callable[..., ChildProcess], scan_probe, module: str
) -> None:
    """With a device already streaming on `pty`: closing it ends the driver within ~1 s, exit 1."""
    driver = start_driver(module, "-p", f"port:={pty.name}", "-p", "timeout:=5.0")
    scan_probe().wait_scans(1, driver)
    pty.close()
    started = time.monotonic()
    assert driver.wait() == 1
    assert time.monotonic() - started < 2.0
    stderr = driver.stderr()
    assert "[ERROR]" in stderr and pty.name in stderr
    driver.assert_no_traceback()
