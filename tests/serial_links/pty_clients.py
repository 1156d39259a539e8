"""Helpers for driving board processes over ptys.

A LIDAR client's DTR/RTS calls on a pty need no help here: run it with the
port's client environment (``PtyPort.client_environment``, or the "modem
lines" line ``fossbot-hil emulate`` prints), as docs/hil.md says.
"""

from __future__ import annotations

import os
import select
import threading
import tty


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
