"""Put the device's bytes on the port: its replies first, then the stream.

In realtime line time passes whether the port took the bytes or not: what
it did not take is lost, as on a UART nobody reads (``overrun_bytes``).
"""

from __future__ import annotations

import threading
import time

from harness.serial_line.pacing import LinePacer, unpaced_chunks
from harness.serial_line.ports import DevicePort
from harness.serial_line.stats import RevolutionSent, ServerCounts
from harness.serial_line.stream_policy import StreamPolicy

__all__ = ["LineWriter"]


class LineWriter:
    """Writes `policy`'s stream and the device's replies; `lock` guards what the harness reads."""

    def __init__(
        self,
        port: DevicePort,
        policy: StreamPolicy,
        counts: ServerCounts,
        lock: threading.Lock,
        *,
        pacer: LinePacer | None,
        baudrate: int,
        bits_per_byte: int = 10,
    ) -> None:
        self.port, self.policy, self.counts, self.lock = port, policy, counts, lock
        self.pacer = pacer
        self._chunk, self._budget = unpaced_chunks(
            baudrate, bits_per_byte, paced_by_hardware=port.paced_by_hardware
        )
        self.reply = bytearray()
        self.stalled = False  # lockstep: the port took less than offered
        self._write_ns = 0  # system time just before the last write to the port
        self.sent: list[RevolutionSent] = []  # every revolution that went out, in order

    @property
    def pending(self) -> bool:
        return bool(self.reply or self.policy.stream)

    def add_reply(self, reply: bytes) -> None:
        """The device's answer, to go out before any more of the stream."""
        if reply:
            self.stalled = False  # new bytes: try the port at once
            self.reply += reply
            self.counts.reply_bytes += len(reply)

    def wait_s(self, now: float, poll_s: float) -> float:
        """With bytes pending: how long the thread may wait for the host before writing."""
        if self.pacer is not None:
            return min(poll_s, max(0.0, self.pacer.due(now) - now))
        # lockstep: more to write at once, or the port took less than
        # offered: retry soon, or slowly while nobody has the other end open.
        if not self.stalled:
            return 0.0
        return poll_s if self.port.peer_present() is False else min(poll_s, 0.002)

    def write(self, now: float) -> None:
        """Write what may go now: unpaced up to a budget, paced chunk by chunk."""
        if self.pacer is None:
            budget = self._budget  # then look at the host again
            while budget > 0 and self.pending:
                buf = self.reply or self.policy.stream
                chunk = bytes(buf[: self._chunk])
                self._write_ns = time.time_ns()
                n = self.port.write(chunk, 0.0)
                self._consumed(buf, n, n, time.monotonic())
                budget -= len(chunk)
                self.stalled = n < len(chunk)
                if self.stalled:
                    return
            return
        while self.pending:
            buf = self.reply or self.policy.stream
            n = self.pacer.allowance(len(buf), now)
            if n == 0:
                return
            self._write_ns = time.time_ns()
            written = self.port.write(bytes(buf[:n]), 0.0)
            with self.lock:
                if buf is self.policy.stream and self.policy.writing_start:
                    self.pacer.mark_revolution(now)
                self.pacer.sent(n, now)
            # Line time passed either way: what the port did not take is lost.
            self.counts.overrun_bytes += n - written
            self._consumed(buf, n, written, now)
            now = time.monotonic()

    def _consumed(self, buf: bytearray, n: int, written: int, now: float) -> None:
        if n <= 0:
            return
        self.counts.bytes_written += written
        if buf is not self.policy.stream:
            del buf[:n]
            return
        done = self.policy.consumed(n, written, now, self._write_ns)
        if done is not None:
            with self.lock:
                self.sent.append(done)
