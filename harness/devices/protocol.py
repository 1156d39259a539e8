"""What a serial front end may ask of an emulated LIDAR: one declared interface.

A device lacking a capability (the LD06 has no requests, motor line or
reboot) declares it absent through ``DeviceDefaults`` instead of leaving the
member out, so the server never probes. Pure.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Protocol, runtime_checkable

from harness.devices.events import Listener
from harness.devices.revolution import Sample

__all__ = ["DeviceDefaults", "LineDevice"]

_NONE: Mapping[str, int] = MappingProxyType({})


@runtime_checkable
class LineDevice(Protocol):
    """An emulated LIDAR as its serial front end sees it.

    ``mode``: "idle", else the scan kind ("scan", "express"; "streaming" for a
    device that streams unasked). ``session`` changes when a scan starts or
    ends: bytes queued before are stale. ``packetized``: the encoder holds a
    partial packet for its next call (the LD06), so a start marker completes
    it. ``follows_motor_line``: the motor follows the board's DTR (``set_motor``).
    """

    listener: Listener | None

    @property
    def mode(self) -> str: ...

    @property
    def session(self) -> int: ...

    @property
    def motor_on(self) -> bool: ...

    @property
    def rebooting(self) -> bool: ...

    @property
    def packetized(self) -> bool: ...

    @property
    def follows_motor_line(self) -> bool: ...

    @property
    def samples_per_packet(self) -> int: ...

    @property
    def counters(self) -> Mapping[str, int]: ...

    @property
    def requests_by_command(self) -> Mapping[str, int]: ...

    def receive(self, data: bytes) -> bytes:
        """Host bytes in; the device's immediate replies out."""
        ...

    def drop_partial_request(self) -> None:
        """The line went quiet inside a request: forget its bytes."""
        ...

    def finish_reset(self) -> bytes:
        """A RESET reboot is over: what the device prints (its banner)."""
        ...

    def set_motor(self, on: bool) -> None:
        """The motor line changed: True runs the motor."""
        ...

    def set_rate(self, rate_hz: float) -> None:
        """The device turns at `rate_hz` from now on (a scenario's LIDAR rate)."""
        ...

    def encode_revolution(self, samples: Sequence[Sample], *, start_ms: float = 0.0) -> bytes:
        """The bytes of one revolution whose first sample was taken at `start_ms`."""
        ...


class DeviceDefaults:
    """The capabilities a device may lack, declared absent (a stream-only device: ``mode``
    and ``encode_revolution`` are its own)."""

    listener: Listener | None = None
    session: int = 0  # never changes: no scan starts or ends
    motor_on: bool = True
    rebooting: bool = False
    packetized: bool = False
    follows_motor_line: bool = False
    samples_per_packet: int = 1
    counters: Mapping[str, int] = _NONE
    requests_by_command: Mapping[str, int] = _NONE

    def receive(self, data: bytes) -> bytes:
        """A device that takes no requests answers none."""
        return b""

    def drop_partial_request(self) -> None:
        """No requests, so no partial one to drop."""

    def finish_reset(self) -> bytes:
        """No RESET, so no banner."""
        return b""

    def set_motor(self, on: bool) -> None:
        """No motor line to follow (``follows_motor_line`` is False)."""

    def set_rate(self, rate_hz: float) -> None:
        """A device whose bytes do not carry its rate need not know it."""
