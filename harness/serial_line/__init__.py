"""The serial line to the board: ports, real-time pacing, and the device server.

``ports`` gives a pty pair (the virtual board) or a named USB-UART (real
HIL), one run at a time (``port_lock``); ``server`` runs an emulated LIDAR
on it in one thread, one module per role (docs/architecture.md lists them);
``device_line`` opens a device's whole line at once.
"""

from harness import lazy_exports

_EXPORTS = {
    "DeviceLine": "device_line",
    "DevicePort": "ports",
    "DeviceServer": "server",
    "LineEvent": "line_watch",
    "LinePacer": "pacing",
    "ModemLines": "modem_lines",
    "PacingReport": "pacing",
    "PortInfo": "ports",
    "PortLock": "port_lock",
    "PtyPort": "ports",
    "RevolutionSent": "stats",
    "SerialPort": "ports",
    "ServerStats": "stats",
    "StreamPolicy": "stream_policy",
    "hold_port": "port_lock",
    "list_serial_ports": "ports",
    "open_device_line": "device_line",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
