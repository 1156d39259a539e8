"""What an emulated device did with the host's bytes, one event each.

A builder whose board driver starts no scan needs to see what it sent and
what the device answered or rejected: devices tell a listener ``DeviceEvent``s
(``emulate -v``, the HIL link's error). Pure.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

HEX_EXCERPT_BYTES = 16  # longer byte strings are cut, with the total length said

# What each protocol error most often means on a bench (the -v log says it once).
ERROR_HINTS: dict[str, str] = {
    "garbage_bytes": "not a request: wrong baud rate, wrong device type, or line noise",
    "bad_checksum": "a request with a payload whose checksum is wrong (damaged or wrong baud)",
    "unknown_command": "a command this device does not know (another LIDAR model's driver?)",
    "truncated": "the line went quiet in the middle of a request",
    "bad_payload": "a known command with a payload of the wrong size",
    "unknown_conf": "GET_LIDAR_CONF for a type or scan mode this device does not list",
    "unsupported_mode": "EXPRESS_SCAN in a scan mode not emulated (use Standard or Express)",
    "refused_scan": "scan refused: the device is in Protection Stop until RESET",
    "ignored_rebooting": "bytes sent while the device rebooted after RESET",
    "ignored_host_bytes": "this device takes no commands (an RPLIDAR driver on an LD06/LD19?)",
}


def hex_excerpt(data: bytes, limit: int = HEX_EXCERPT_BYTES) -> str:
    """Bytes as spaced upper-case hex, cut after `limit` bytes."""
    shown = data[:limit].hex(" ").upper()
    return shown + (f" ... ({len(data)} bytes)" if len(data) > limit else "")


@dataclass(frozen=True)
class DeviceEvent:
    """One request the device handled, or one protocol error it counted."""

    kind: str  # "request", or the counter the error raised ("bad_checksum", ...)
    data: bytes  # the host's bytes this is about
    command: str = ""  # the request's name, e.g. "GET_INFO"
    reply: bytes = b""  # what the device answered at once
    note: str = ""  # what followed, e.g. "streaming standard nodes"

    @property
    def is_error(self) -> bool:
        return self.kind != "request"

    def text(self) -> str:
        """One log line: request, its bytes, the answer; or the error and its bytes."""
        if not self.is_error:
            answer = (
                f"answered {len(self.reply)} bytes: {hex_excerpt(self.reply)}"
                if self.reply
                else "no answer (none is due)"
            )
            note = f"; {self.note}" if self.note else ""
            return f"request {self.command}  {hex_excerpt(self.data)}  -> {answer}{note}"
        what = f" {self.command}" if self.command else ""
        note = self.note or ERROR_HINTS.get(self.kind, "")
        data = f"  {hex_excerpt(self.data)}" if self.data else ""
        return f"error {self.kind}{what}{data}" + (f"  ({note})" if note else "")


Listener = Callable[[DeviceEvent], None]
