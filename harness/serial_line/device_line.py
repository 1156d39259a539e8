"""Open an emulated LIDAR's whole line at once: its port and the server that runs it.

`emulate` and the board session both put a device on a USB-UART (only when
named) or a pty pair: one function, so they cannot drift apart. The server
comes back unstarted (``emulate`` builds its simulation first) and each
caller closes the server, then the port.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from harness.serial_line.ports import PtyPort, SerialPort
from harness.serial_line.server import DeviceServer, Mode, NextStart

if TYPE_CHECKING:
    from harness.devices.protocol import LineDevice

__all__ = ["DeviceLine", "open_device_line"]


@dataclass
class DeviceLine:
    """A device, the port it is served on and its server."""

    device: LineDevice
    port: PtyPort | SerialPort
    server: DeviceServer

    @property
    def name(self) -> str:
        """The path a client opens: the pty's slave, or the named port."""
        return self.port.slave_path if isinstance(self.port, PtyPort) else self.port.name


def open_device_line(
    device: LineDevice,
    *,
    port: str | None,
    baudrate: int,
    mode: Mode,
    revolution_period_s: float,
    next_start: NextStart = "extra",
    continuous: bool = False,
    listener: Callable[[Any], None] | None = None,
    damage: Any = None,
) -> DeviceLine:
    """`device` on the USB-UART `port` (``ConfigError`` if it cannot be opened), or on a
    new pty pair when `port` is None, with its server (not started); `damage` is a
    ``harness.faults.link.LineDamage`` for the line's bytes."""
    line: PtyPort | SerialPort = PtyPort() if port is None else SerialPort(port, baudrate)
    try:
        server = DeviceServer(
            device,
            line,
            mode=mode,
            baudrate=baudrate,
            revolution_period_s=revolution_period_s,
            next_start=next_start,
            continuous=continuous,
            listener=listener,
        )
    except BaseException:
        line.close()
        raise
    server.damage = damage
    return DeviceLine(device, line, server)
