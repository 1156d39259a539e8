"""The serial line to the board: ports, real-time pacing, and the device server.

``ports`` gives a pty pair (the virtual board) or a named USB-UART (real
HIL), which ``port_lock`` lets one run use at a time; ``modem_lines``
carries a pyserial client's DTR and RTS to a pty, which has none (its
``modem_shim`` folder goes on the client's PYTHONPATH); ``pacing`` paces
bytes at the line rate that ptys ignore; ``server`` runs an emulated LIDAR
from ``harness.devices`` on a port in one thread.
"""

from __future__ import annotations

from harness.serial_line.modem_lines import ModemLines
from harness.serial_line.pacing import LinePacer, PacingReport
from harness.serial_line.port_lock import PortLock, hold_port
from harness.serial_line.ports import DevicePort, PortInfo, PtyPort, SerialPort, list_serial_ports
from harness.serial_line.server import DeviceServer, RevolutionSent, ServerStats

__all__ = [
    "DevicePort",
    "DeviceServer",
    "LinePacer",
    "ModemLines",
    "PacingReport",
    "PortInfo",
    "PortLock",
    "PtyPort",
    "RevolutionSent",
    "SerialPort",
    "ServerStats",
    "hold_port",
    "list_serial_ports",
]
