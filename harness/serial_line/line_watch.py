"""The line around the bytes: the board's DTR (the motor), the client, its baud rate.

A pty shows whether a client has it open and the baud it set (shared
termios); a USB-UART shows neither but carries DTR on DSR or CTS. Polled
before host bytes reach the device, so a DTR set before a request is seen
first, as on a wire; each change is a ``LineEvent`` (`emulate -v`, ``diagnosis``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from harness.serial_line.ports import DevicePort
from harness.serial_line.stats import LineState, ServerCounts

if TYPE_CHECKING:
    from harness.devices.protocol import LineDevice

__all__ = ["LineEvent", "LineWatch"]

DTR_POLL_S = 0.02
BAUD_SETTLE_S = 0.1  # a client sets its baud just after it opens: look after this


@dataclass(frozen=True)
class LineEvent:
    """Something on the line rather than in the protocol: a client came or went,
    its baud rate, the motor line. Logged like a device's events."""

    kind: str  # client_opened, client_closed, wrong_baud, baud_ok, motor, motor_off, rts
    note: str

    @property
    def is_error(self) -> bool:
        return self.kind in ("wrong_baud", "motor_off")

    def text(self) -> str:
        return f"{'error ' + self.kind + ': ' if self.is_error else ''}{self.note}"


class LineWatch:
    """Follows `port`'s modem line and client for `device` (one thread calls it).

    `motor_on_when_dtr`: the A1 dev kit runs the motor with DTR deasserted
    (the rplidar package's ``setDTR(False)``), hence False by default.
    `motor_on_without_dtr`: a pty has no DTR to follow, so the board's
    driver is taken to have started the motor.
    """

    def __init__(
        self,
        device: LineDevice,
        port: DevicePort,
        counts: ServerCounts,
        *,
        baudrate: int,
        follow_dtr: bool = True,
        motor_on_when_dtr: bool = False,
        motor_on_without_dtr: bool = True,
        tell: Callable[[Any], None] = lambda event: None,
        changed: Callable[[], None] = lambda: None,
    ) -> None:
        self.device, self.port, self.counts = device, port, counts
        self.baudrate, self.follow_dtr = baudrate, follow_dtr
        self.motor_on_when_dtr, self.motor_on_without_dtr = motor_on_when_dtr, motor_on_without_dtr
        self._tell, self._changed = tell, changed
        self.dtr: bool | None = None
        self._polled = 0.0
        self._peer: bool | None = None  # the client has the port open (pty only)
        # Ptys tell whether a client has them open; a real UART cannot (None).
        self.peer_seen: bool | None = None if port.peer_present() is None else False
        self._peer_since = 0.0
        self.host_baud: int | None = None
        self.wrong_baud_rate: int | None = None

    def start_motor(self) -> None:
        """At start: with no DTR to follow, the motor runs (the driver is taken to start it)."""
        if not self.device.follows_motor_line or not self.motor_on_without_dtr:
            return
        if not self.follow_dtr or self.port.dtr_asserted() is None:
            self.device.set_motor(True)

    def poll(self, now: float, *, force: bool = False) -> None:
        """Look at the client and DTR, at most every ``DTR_POLL_S`` unless `force`d."""
        if not force and now - self._polled < DTR_POLL_S:
            return
        self._polled = now
        self._poll_peer(now)
        if not self.follow_dtr:
            return
        dtr = self.port.dtr_asserted()
        if dtr is None or dtr == self.dtr:
            return
        self.dtr = dtr
        if self.device.follows_motor_line:
            on = dtr if self.motor_on_when_dtr else not dtr
            self.device.set_motor(on)
            self._changed()
            line = "asserted" if dtr else "deasserted"
            self._tell(LineEvent("motor", f"board's DTR {line}: motor {'on' if on else 'off'}"))

    def state(self, peer_present: bool | None) -> LineState:
        """The line's fields of ``ServerStats``; `peer_present` as the port says it now."""
        return LineState(
            peer_present, self.peer_seen, self.host_baud, self.wrong_baud_rate, self.dtr
        )

    def _poll_peer(self, now: float) -> None:
        """Whether a client has the port open, and at which baud (ptys tell both)."""
        peer = self.port.peer_present()
        if peer is None:
            return
        if self.peer_seen is None:
            self.peer_seen = False
        if peer != self._peer:
            self._peer = peer
            if peer:
                self.peer_seen = True
                self._peer_since = now
                self.counts.client_opens += 1
                self._tell(LineEvent("client_opened", f"a client opened {self.port.name}"))
            elif self.peer_seen:
                self.host_baud = None
                self._tell(LineEvent("client_closed", f"the client closed {self.port.name}"))
        if not peer or now - self._peer_since < BAUD_SETTLE_S:
            return
        self._check_baud()

    def _check_baud(self) -> None:
        baud = self.port.host_baud()
        if baud is None or baud == self.host_baud:
            return
        self.host_baud = baud
        if baud == self.baudrate:
            self._tell(LineEvent("baud_ok", f"the client's line is at {baud} baud"))
            return
        self.counts.wrong_baud += 1
        self.wrong_baud_rate = baud
        said = f"the client set its line to {baud} baud; this device talks at {self.baudrate}"
        said += " (a pty carries the bytes anyway, a real cable would garble them)"
        self._tell(LineEvent("wrong_baud", said))
