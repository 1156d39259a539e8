"""The host's bytes into the device, and the device's timed events that follow them.

A request cut by ``request_gap_s`` of quiet is dropped; a RESET's banner
comes ``reset_s`` later; a scan that started or ended makes the queued
stream stale (``StreamPolicy.device_changed``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from harness.serial_line.line_watch import LineWatch
from harness.serial_line.line_writer import LineWriter
from harness.serial_line.stats import ServerCounts
from harness.serial_line.stream_policy import StreamPolicy

if TYPE_CHECKING:
    from harness.devices.protocol import LineDevice

__all__ = ["HostBytes"]


class HostBytes:
    """Feeds `device` what the host sent; keeps its reboot and partial-request timers."""

    def __init__(
        self,
        device: LineDevice,
        parts: tuple[StreamPolicy, LineWatch, LineWriter],
        counts: ServerCounts,
        *,
        reset_s: float,
        request_gap_s: float,
        changed: Callable[[], None],
    ) -> None:
        self.device, self.counts = device, counts
        self.policy, self.watch, self.writer = parts
        self.reset_s = reset_s  # how long a RESET reboot lasts before the banner
        self.request_gap_s = request_gap_s  # line quiet this long: a partial request is dropped
        self._changed = changed
        self._reboot_at: float | None = None
        self._last_rx: float | None = None  # host bytes since the line was last quiet

    def received(self, data: bytes) -> None:
        """Host bytes: to the device, its replies to the writer."""
        # A modem line set before these bytes were written (setDTR, then a
        # request) is seen first, as on a wire; so is "a client opened".
        self.watch.poll(time.monotonic(), force=True)
        self.counts.host_bytes += len(data)
        self.counts.host_reads += 1
        self._last_rx = time.monotonic()
        reply = self.device.receive(bytes(data))
        self._changed()
        self.writer.add_reply(reply)
        if self.device.rebooting and self._reboot_at is None:
            self._reboot_at = time.monotonic() + self.reset_s
        self.policy.device_changed()

    def housekeeping(self, now: float) -> None:
        """The device's timed events: the end of a RESET reboot, a request cut short."""
        if self._reboot_at is not None and now >= self._reboot_at:
            self._reboot_at = None
            self.writer.add_reply(self.device.finish_reset())
        if self._last_rx is not None and now - self._last_rx >= self.request_gap_s:
            self._last_rx = None
            self.device.drop_partial_request()
