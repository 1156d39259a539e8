"""Helpers for driving third-party LIDAR clients and board processes over ptys."""

from __future__ import annotations

import errno
import os
import select
import threading
import tty

import serial.serialposix


def tolerate_missing_dtr_on_pty() -> None:
    """Let pyserial clients run on a pty: a pty has no DTR line (ENOTTY), a USB-UART does.

    The RPLIDAR clients toggle DTR to drive the A1's motor. Only that one
    error is ignored; everything else the client does is unchanged.
    """
    original = serial.serialposix.Serial._update_dtr_state
    if getattr(original, "tolerant", False):
        return

    def update(self: serial.serialposix.Serial) -> None:
        try:
            original(self)
        except OSError as err:
            if err.errno != errno.ENOTTY:
                raise

    update.tolerant = True  # type: ignore[attr-defined]
    serial.serialposix.Serial._update_dtr_state = update


class NullModem:
    """Two pty pairs joined back to back: a cable between two serial device paths.

    The harness opens `harness_end` as if it were a USB-UART; the board side
    opens `board_end`. `cut()` unplugs it, as a yanked adapter would.
    """

    def __init__(self) -> None:
        self._a_master, a_slave = os.openpty()
        self._b_master, b_slave = os.openpty()
        for fd in (a_slave, self._a_master, b_slave, self._b_master):
            tty.setraw(fd)
        self.harness_end, self.board_end = os.ttyname(a_slave), os.ttyname(b_slave)
        self._slaves = (a_slave, b_slave)  # held open so neither end sees EIO early
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._pump, daemon=True)
        self._thread.start()

    def _pump(self) -> None:
        pairs = {self._a_master: self._b_master, self._b_master: self._a_master}
        while not self._stop.is_set():
            ready, _, _ = select.select(list(pairs), [], [], 0.05)
            for fd in ready:
                try:
                    data = os.read(fd, 4096)
                    os.write(pairs[fd], data)
                except OSError:
                    continue

    def cut(self) -> None:
        """Unplug: stop copying and close everything, so both ends see the line die."""
        self._stop.set()
        self._thread.join(timeout=2)
        for fd in (self._a_master, self._b_master, *self._slaves):
            try:
                os.close(fd)
            except OSError:
                pass
