"""Pace bytes at a serial line's real rate, and measure how well that went.

Linux ptys ignore the baud rate, so real-time emulation paces itself. Due
times count from the burst's start, never from "now", so sleep overshoot
does not add up into a slower line. Pure timing: the caller passes ``now``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise


@dataclass(frozen=True)
class PacingReport:
    """How close the line came to its nominal rate and revolution period."""

    bytes_paced: int
    achieved_bytes_per_s: float | None  # over busy stretches only (idle gaps excluded)
    nominal_bytes_per_s: float
    mean_rate_error_pct: float | None  # (achieved / nominal - 1) * 100
    revolutions: int
    period_jitter_p99_ms: float | None  # p99 of |start interval - nominal period|
    period_mean_ms: float | None


def p99(values: list[float]) -> float:
    """Nearest-rank 99th percentile (the maximum for fewer than 100 values)."""
    ordered = sorted(values)
    return ordered[max(0, math.ceil(0.99 * len(ordered)) - 1)]


class LinePacer:
    """When the next bytes may go out on a line of `baudrate`, and how it went.

    Byte i of a burst is due at ``start + i * byte_time``; a new burst starts on
    an idle line or `max_lag_s` behind (catching up would beat the line rate).
    Chunks of `chunk_s` keep the stream continuous while the writer wakes about
    once a millisecond.
    """

    def __init__(
        self,
        baudrate: int,
        bits_per_byte: int = 10,
        *,
        chunk_s: float = 0.001,
        max_lag_s: float = 0.005,
    ) -> None:
        if baudrate <= 0 or bits_per_byte <= 0:
            raise ValueError("baudrate and bits_per_byte must be positive")
        self.baudrate, self.bits_per_byte = baudrate, bits_per_byte
        self.byte_time_s = bits_per_byte / baudrate
        self.chunk_bytes = max(1, int(chunk_s / self.byte_time_s))
        self.max_lag_s = max_lag_s
        self._burst_start: float | None = None
        self._burst_bytes = 0  # bytes scheduled in the current burst
        self._first_write = self._last_write = 0.0
        self._last_chunk = 0
        self._busy_bytes = 0  # closed bursts: bytes between first and last chunk write
        self._busy_time = 0.0
        self.bytes_paced = 0
        self.revolution_starts: list[float] = []

    @property
    def nominal_bytes_per_s(self) -> float:
        return 1.0 / self.byte_time_s

    def due(self, now: float) -> float:
        """When the next chunk may be written: `now` if the line is idle or far behind."""
        free_at = self.free_at()
        if free_at is None or now - free_at > self.max_lag_s:
            return now
        return free_at

    def free_at(self) -> float | None:
        """When the line finishes the bytes already sent (None before any)."""
        if self._burst_start is None:
            return None
        return self._burst_start + self._burst_bytes * self.byte_time_s

    def allowance(self, pending: int, now: float) -> int:
        """How many of `pending` bytes may be written at `now` (0: not yet due)."""
        if pending <= 0 or now < self.due(now):
            return 0
        return min(pending, self.chunk_bytes)

    def sent(self, n: int, now: float) -> None:
        """Record that `n` bytes were handed to the line at `now`."""
        if n <= 0:
            return
        free_at = self.free_at()
        if free_at is None or now - free_at > self.max_lag_s:
            self._close_burst()
            self._burst_start = now
            self._burst_bytes = 0
            self._first_write = now
        self._burst_bytes += n
        self._last_write = now
        self._last_chunk = n
        self.bytes_paced += n

    def mark_revolution(self, now: float) -> None:
        """Record the write time of a revolution's first byte."""
        self.revolution_starts.append(now)

    def _close_burst(self) -> None:
        if self._burst_start is None:
            return
        self._busy_bytes += self._burst_bytes - self._last_chunk
        self._busy_time += self._last_write - self._first_write
        self._burst_start = None

    def report(self, period_s: float | None = None) -> PacingReport:
        """Achieved rate over busy stretches (up to each burst's last chunk), and start jitter."""
        busy_bytes = self._busy_bytes
        busy_time = self._busy_time
        if self._burst_start is not None:
            busy_bytes += self._burst_bytes - self._last_chunk
            busy_time += self._last_write - self._first_write
        achieved = busy_bytes / busy_time if busy_time > 0 else None
        nominal = self.nominal_bytes_per_s
        error = (achieved / nominal - 1.0) * 100.0 if achieved is not None else None
        intervals = [b - a for a, b in pairwise(self.revolution_starts)]
        jitter = mean = None
        if intervals:
            mean = sum(intervals) / len(intervals) * 1000.0
            if period_s is not None:
                jitter = p99([abs(i - period_s) * 1000.0 for i in intervals])
        starts = len(self.revolution_starts)
        return PacingReport(self.bytes_paced, achieved, nominal, error, starts, jitter, mean)


LOCKSTEP_CHUNK = 4096  # bytes offered per write in lockstep (a pty takes them at once)
HARDWARE_CHUNK_S = 0.02  # a real UART: offer 20 ms of line time per write


def unpaced_chunks(
    baudrate: int, bits_per_byte: int = 10, *, paced_by_hardware: bool = False
) -> tuple[int, int]:
    """Lockstep: bytes per write, and per look at the host.

    A pty takes everything at once; a UART drains at its baud, so about 20 ms
    of line time a write, so a request is answered within that.
    """
    if paced_by_hardware:
        chunk = max(16, int(baudrate / bits_per_byte * HARDWARE_CHUNK_S))
        return chunk, chunk
    return LOCKSTEP_CHUNK, 16 * LOCKSTEP_CHUNK
