"""Run an emulated LIDAR on a serial line, in one background thread.

The thread owns the device: nothing else may touch it while the server
runs. The roles are parts (``stream_policy``, ``line_watch``, ``host_bytes``,
``line_writer``, ``pushes``); what stays here is the thread, the bounded
waits, and errors carried from the thread to the caller.
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from harness.errors import LinkError
from harness.serial_line.host_bytes import HostBytes
from harness.serial_line.line_watch import LineEvent, LineWatch
from harness.serial_line.line_writer import LineWriter
from harness.serial_line.pacing import LinePacer
from harness.serial_line.ports import DevicePort
from harness.serial_line.pushes import Pushes
from harness.serial_line.realtime_priority import raise_to_realtime
from harness.serial_line.stats import RevolutionSent, ServerCounts, ServerStats, snapshot
from harness.serial_line.stream_policy import Mode, NextStart, StreamPolicy

if TYPE_CHECKING:
    from harness.devices.protocol import LineDevice

__all__ = ["DeviceServer", "LineEvent", "Mode", "NextStart", "RevolutionSent", "ServerStats"]

_STOP_JOIN_S = 2.0


def _drain(fd: int) -> None:
    with contextlib.suppress(OSError):  # BlockingIOError: empty
        while os.read(fd, 4096):
            pass


class DeviceServer:
    """An emulated LIDAR `device` served on `port` by one background thread.

    An error in the thread stops it; it is kept in ``error`` and raised as
    ``LinkError`` by the next ``send_revolution``/``wait_idle``/``close``.
    """

    def __init__(
        self,
        device: LineDevice,
        port: DevicePort,
        *,
        mode: Mode = "lockstep",
        baudrate: int = 115200,
        revolution_period_s: float = 0.1,
        next_start: NextStart = "extra",
        bits_per_byte: int = 10,
        follow_dtr: bool = True,
        motor_on_when_dtr: bool = False,
        motor_on_without_dtr: bool = True,
        reset_s: float = 0.1,
        request_gap_s: float = 0.1,
        poll_s: float = 0.01,
        listener: Callable[[Any], None] | None = None,
        continuous: bool = False,
    ) -> None:
        self.device, self.port, self.baudrate = device, port, baudrate
        self.mode: Mode = mode
        self.next_start: NextStart = next_start
        self.continuous, self.poll_s = continuous, poll_s
        # Told (on the server thread) of line events and, through the device, of
        # each request and protocol error: what `emulate -v` prints.
        self.listener = listener
        if listener is not None:
            device.listener = listener
        self._counts = ServerCounts()
        self._lock = threading.Lock()
        self._changed = threading.Event()  # device state may have changed
        self.policy = StreamPolicy(
            device,
            self._counts,
            mode=mode,
            period_s=revolution_period_s,
            next_start=next_start,
            continuous=continuous,
            tell=self._tell,
            on_bytes=self._unstall,
        )
        self.watch = LineWatch(
            device,
            port,
            self._counts,
            baudrate=baudrate,
            follow_dtr=follow_dtr,
            motor_on_when_dtr=motor_on_when_dtr,
            motor_on_without_dtr=motor_on_without_dtr,
            tell=self._tell,
            changed=self._changed.set,
        )
        self.pacer = LinePacer(baudrate, bits_per_byte) if mode == "realtime" else None
        self.writer = LineWriter(
            port,
            self.policy,
            self._counts,
            self._lock,
            pacer=self.pacer,
            baudrate=baudrate,
            bits_per_byte=bits_per_byte,
        )

        self.host = HostBytes(
            device,
            (self.policy, self.watch, self.writer),
            self._counts,
            reset_s=reset_s,
            request_gap_s=request_gap_s,
            changed=self._changed.set,
        )
        # The harness's side: pushes waiting for the thread, the idle stream.
        self.pushes = Pushes(self._lock, self._counts, realtime=mode == "realtime")
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self._thread = threading.Thread(target=self._run, name="serial-device-server", daemon=True)
        self._started = False
        self._closed = False
        # Realtime mode: whether the server thread got SCHED_FIFO (None until it runs).
        self.realtime_priority: bool | None = None
        self._error: LinkError | None = None
        self._error_raised = False

    # -- the parts' settings, as callers name them ----------------------------

    @property
    def period_s(self) -> float:
        """The revolution period: pushes without their own, and lockstep timestamps."""
        return self.policy.period_s

    @period_s.setter
    def period_s(self, value: float) -> None:
        self.policy.period_s = value

    @property
    def damage(self) -> Any:
        """A ``harness.faults.link.LineDamage`` spoiling each revolution's bytes, or None."""
        return self.policy.damage

    @damage.setter
    def damage(self, value: Any) -> None:
        self.policy.damage = value

    # ----------------------------------------------------------- harness side

    def start(self) -> DeviceServer:
        if self._started:
            raise RuntimeError("DeviceServer already started")
        self._started = True
        self.policy.t0 = time.monotonic()
        self._thread.start()
        return self

    def __enter__(self) -> DeviceServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def error(self) -> LinkError | None:
        """What stopped the server thread, if anything did."""
        return self._error

    @property
    def unit_samples(self) -> int:
        """Samples in one packet of the device's stream (1 for RPLIDAR nodes)."""
        return self.policy.unit

    @property
    def marker_samples(self) -> int:
        """Samples in the last start marker: what "replace" takes off the next revolution."""
        return self.policy.marker_size

    def send_revolution(
        self, samples: Sequence[Any], tick: int, period_s: float | None = None
    ) -> int:
        """Queue one revolution; returns its id (``delivery_of``).

        `period_s`: in real time, how long it lasts (a drifting rate); default the
        server's. In continuous lockstep a push also ends the idle stream.
        """
        self._check()
        push_id = self.pushes.push(samples, tick, period_s or self.period_s)
        self._wake()
        return push_id

    def stream_idle(
        self, samples: Sequence[Any] | None = None, period_s: float | None = None
    ) -> None:
        """Continuous: keep streaming `samples` (default the last sent) until the next push."""
        if not self.continuous:
            raise RuntimeError("stream_idle needs a continuous server")
        self._check()
        self.pushes.stream_idle(samples, period_s or self.period_s)
        self._wake()

    def end_idle(self, timeout: float) -> RevolutionSent | None:
        """Continuous lockstep: stop the idle stream, wait (at most `timeout` s) for its
        revolution to be out; returns the last repeat since the last push, or None.

        The stream ends on a whole start marker however many idle revolutions went
        out, so the pushes that follow are the same bytes (same seed, same bytes).
        """
        self._check()
        if not self.pushes.end_idle():
            return None
        self._wake()
        self.pushes.quiet.wait(max(0.0, timeout))
        self._check()
        with self._lock:
            last = self.writer.sent[-1] if self.writer.sent else None
        return last if last is not None and last.repeat else None

    def align_stream(self) -> None:
        """Lockstep: end what was sent so far on a whole start marker before the next push,
        so the pushes that follow are the same bytes however many went before (a warm-up
        retried, say); see ``end_idle``."""
        self._check()
        self.pushes.align()
        self._wake()

    def delivery_of(self, push_id: int) -> RevolutionSent | None:
        """When the pushed revolution `push_id` went out whole, or None (not yet, or never)."""
        with self._lock:
            for delivery in reversed(self.writer.sent):
                if delivery.push_id == push_id:
                    return delivery
                if delivery.push_id is not None and delivery.push_id < push_id:
                    return None
        return None

    def wait_idle(self, timeout: float) -> bool:
        """Wait (at most `timeout` s) until everything queued was written; False on timeout."""
        self._check()
        done = self.pushes.idle.wait(max(0.0, timeout))
        self._check()
        if done and not self._thread.is_alive() and self._started and not self._closed:
            raise LinkError("serial device server stopped")
        return done

    def wait_until(self, predicate: Callable[[LineDevice], bool], timeout: float) -> bool:
        """Wait (at most `timeout` s) until `predicate(device)` holds, e.g. "scanning".

        Re-checked after host bytes or a DTR change, and every 50 ms; simple
        attributes (``mode``, ``motor_on``) are safe to read from here.
        """
        self._check()
        deadline = time.monotonic() + max(0.0, timeout)
        while not predicate(self.device):
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self._changed.wait(min(left, 0.05))
            self._changed.clear()
            self._check()
        return True

    def deliveries(self) -> list[RevolutionSent]:
        """When each revolution went out, in order."""
        with self._lock:
            return list(self.writer.sent)

    def stats(self) -> ServerStats:
        with self._lock:
            pacing = self.pacer.report(self.period_s) if self.pacer is not None else None
            counts = ServerCounts(**vars(self._counts))
        try:
            peer = self.port.peer_present() if not self._closed else None
        except LinkError:
            peer = None
        return snapshot(self.mode, counts, self.watch.state(peer), self.device, pacing)

    def close(self, timeout: float = _STOP_JOIN_S) -> None:
        """Stop the thread and join it (bounded); the port stays open (its owner closes it).

        Raises the thread's error if no earlier call has raised it.
        """
        if self._closed:
            return
        self._closed = True
        self._stop.set()
        self._wake()
        if self._started:
            self._thread.join(timeout)
        if self._thread.is_alive():
            raise LinkError(f"serial device server did not stop within {timeout:g} s")
        os.close(self._wake_r)
        os.close(self._wake_w)
        if self._error is not None and not self._error_raised:
            self._error_raised = True
            raise self._error

    def _check(self) -> None:
        if self._error is not None:
            self._error_raised = True
            raise self._error
        if self._closed:
            raise LinkError("serial device server is closed")
        if not self._started:
            raise RuntimeError("DeviceServer not started")

    def _wake(self) -> None:
        with contextlib.suppress(OSError):  # full (a wake-up is pending anyway) or closed
            os.write(self._wake_w, b"w")

    def _tell(self, event: Any) -> None:
        if self.listener is not None:
            self.listener(event)

    def _unstall(self) -> None:
        self.writer.stalled = False  # new bytes: try the port at once

    # ------------------------------------------------------------- the thread

    def _run(self) -> None:
        try:
            if self.mode == "realtime":
                self.realtime_priority = raise_to_realtime()
            self.watch.start_motor()
            while not self._stop.is_set():
                self._step()
        except BaseException as err:  # noqa: BLE001 - kept and re-raised in the harness thread
            if isinstance(err, LinkError):
                self._error = err
            else:
                text = " ".join(str(err).split())
                wrapped = LinkError(f"serial device server failed: {type(err).__name__}: {text}")
                wrapped.__cause__ = err
                self._error = wrapped
        finally:
            self.pushes.idle.set()
            self._changed.set()

    def _step(self) -> None:
        now = time.monotonic()
        self.watch.poll(now)
        self.host.housekeeping(now)
        self._next_revolution(now)
        data = self.port.read(4096, self._read_timeout(time.monotonic()), self._wake_r)
        _drain(self._wake_r)
        if data:
            self.host.received(data)
        now = time.monotonic()
        self._next_revolution(now)
        self.writer.write(now)
        self.pushes.settle(self.writer.pending)

    def _read_timeout(self, now: float) -> float:
        if self.writer.pending:
            return self.writer.wait_s(now, self.poll_s)
        pushes = self.pushes
        at = self.policy.next_action_at(now, pushed=pushes.waiting, idling=pushes.idling)
        return self.poll_s if at is None else min(self.poll_s, max(0.0, at - now))

    def _next_revolution(self, now: float) -> None:
        if self.policy.stream:
            return
        taken = self.pushes.take(lambda: self.policy.slot_open(now))
        self.policy.advance(
            now,
            taken.push,
            whole_marker=taken.whole_marker,
            idle_request=taken.idle_request,
            idling=taken.idling,
        )
        if taken.whole_marker:
            self.pushes.quiet.set()
