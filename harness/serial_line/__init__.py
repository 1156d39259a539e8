"""The serial line to the board: ports, real-time pacing, and the device server.

``ports`` gives a pty pair (the virtual board) or a named USB-UART (real
HIL), which ``port_lock`` lets one run use at a time; ``modem_lines``
carries a pyserial client's DTR and RTS to a pty, which has none (its
``modem_shim`` folder goes on the client's PYTHONPATH); ``server`` runs an
emulated LIDAR from ``harness.devices`` on a port in one thread, composed
of one part per role: ``stream_policy`` (what goes out next; pure),
``line_watch`` (DTR, the client, its baud), ``host_bytes`` (requests in),
``line_writer`` with ``pacing`` (bytes out at the line rate that ptys
ignore), ``pushes`` (the harness's side) and ``stats`` (the counts, read by
``diagnosis``). ``device_line`` opens a device's whole line at once.
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
