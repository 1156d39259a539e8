"""Run an emulated LIDAR on a serial line, in one background thread.

The harness thread hands over revolutions (``send_revolution``); the server
thread answers host requests, follows DTR, encodes revolutions with the
device and writes them, either as fast as the board takes them (lockstep)
or at the line's real rate with revolutions on the sensor's period
(realtime). The thread owns the device: nothing else may touch it while the
server runs.

The start of the next revolution (lockstep)
-------------------------------------------
A LIDAR driver publishes revolution k only when the start of revolution k+1
arrives (the RPLIDAR start flag; the LD06 angle wrap). In lockstep the
harness sends k+1 only after the answers to k, so without help the run
would deadlock. After every revolution the server therefore also writes a
*start marker*: the start of a sweep, encoded by the device like the start
of any revolution, at the first angles of the revolution just sent, every
reading "no return" (distance 0, quality 0). Its size: one node for an
RPLIDAR standard scan; for the LD06 the samples that complete the packet
the encoder holds open (12 - N mod 12 for N-sample revolutions, or 12), so
that the next revolution starts on a packet boundary and no packet mixes
the marker's angles with the next sweep's (a host would interpolate such a
packet across the whole circle; the vendor driver drops it). What happens
when k+1 arrives is the ``next_start`` policy:

``"extra"`` (default): k+1 is sent whole; the marker is extra.
    The `rplidar` package (the FOSSBot driver) yields k at the marker, keeps
    no reading with quality 0 or distance 0, and drops the marker-only
    "revolution" that k+1's start flag closes (it has no more than
    ``min_len`` readings): it sees every revolution exactly as sent. A
    driver that publishes every start-to-start stretch, however short (the
    Slamtec SDK behind ``rplidar_ros``), would publish one extra near-empty
    scan per revolution: use "replace" there. An LD06 driver's frame k+1
    starts with the marker's no-return points, at the same angles as
    k+1's first readings.
``"replace"``: the marker stands in for the first ``marker_samples`` of
    k+1, which are not sent. No extra revolutions in any driver, but those
    readings are "no return": the link must apply the same change to the
    scan it judges.

Either way the byte stream is a pure function of the revolutions pushed:
the marker goes out after every revolution whatever the timing. In
realtime mode the next revolution normally follows on its own; the marker is
sent only when the next revolution is late at its due time (an underrun),
and the same policy applies when it comes. Express scans get no marker:
their capsules carry no start flag and the encoder holds back a capsule
until the next one starts, so in lockstep the end of each express
revolution waits for the next push (use standard scans, or realtime).

A device that never falls silent (``continuous``)
-------------------------------------------------
A real device streams from its SCAN request until its STOP, whatever the
host does; a driver may wait for bytes with no timeout (rplidar-roboticia
does). With ``continuous`` the server does the same for a whole run of
scenarios: in realtime, when the next revolution is late at its slot, the
start marker goes out as above and, if nothing came within half a period,
the last revolution goes out again (a *repeat*), and so on each period; in
lockstep, revolutions go out as pushed while a scenario runs, and between
scenarios (``stream_idle``, until the next push or ``end_idle``) the last
revolution goes out again every period. ``stream_idle(samples)`` also sets
what to stream before anything was pushed (an empty room, say). Repeats
are marked in ``deliveries()``; a pushed revolution's delivery is found by
the id ``send_revolution`` returned (``delivery_of``).
"""

from __future__ import annotations

import dataclasses
import inspect
import os
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from harness.errors import LinkError
from harness.serial_line.pacing import LinePacer, PacingReport
from harness.serial_line.ports import DevicePort
from harness.serial_line.realtime_priority import raise_to_realtime

Mode = Literal["lockstep", "realtime"]
NextStart = Literal["extra", "replace"]

_LOCKSTEP_CHUNK = 4096  # bytes offered per write in lockstep (a pty takes them at once)
_HARDWARE_CHUNK_S = 0.02  # a real UART: offer 20 ms of line time per write
_DTR_POLL_S = 0.02
_BAUD_SETTLE_S = 0.1  # a client sets its baud just after it opens: look after this
_STOP_JOIN_S = 2.0


@dataclass(frozen=True)
class RevolutionSent:
    """When a revolution went out: the first and the last of its own bytes."""

    tick: int
    started_at: float  # time.monotonic()
    finished_at: float
    push_id: int | None = None  # send_revolution's id; None for a repeat
    # System time (ns) just before the write that carried the revolution's last
    # byte: every scan a driver made of it is published after this.
    written_ns: int = 0
    repeat: bool = False  # the device sent an earlier revolution again (continuous)


@dataclass(frozen=True)
class LineEvent:
    """Something on the line rather than in the protocol: a client came or went,
    its baud rate, the motor line. Logged like a device's events."""

    kind: str  # client_opened, client_closed, wrong_baud, baud_ok, motor, motor_off
    note: str

    @property
    def is_error(self) -> bool:
        return self.kind in ("wrong_baud", "motor_off")

    def text(self) -> str:
        return f"{'error ' + self.kind + ': ' if self.is_error else ''}{self.note}"


@dataclass(frozen=True)
class ServerStats:
    """Counters of one server run; pacing figures only in realtime mode."""

    mode: str
    bytes_written: int
    reply_bytes: int
    host_bytes: int  # bytes the board sent us
    host_reads: int  # reads that brought host bytes (fed to device.receive)
    requests_seen: int | None  # well-formed requests, where the device counts them
    revolutions_sent: int
    revolutions_dropped: int  # the device encoded nothing (not scanning)
    revolutions_superseded: int  # realtime: replaced by a newer one before their slot
    revolutions_repeated: int  # continuous: the last revolution sent again (nothing new came)
    markers_sent: int
    stream_bytes_dropped: int  # unsent revolution bytes dropped when the device stopped
    overrun_bytes: int  # realtime: bytes the line "sent" that the port did not take
    underruns: int  # realtime: the next revolution was late at its slot
    revolutions_whole: int  # revolutions whose every byte the port took
    revolutions_cut: int  # revolutions whose remaining bytes a request (e.g. STOP) cut off
    motor_off_revolutions: int  # scanning was asked for, but the motor was off: nothing sent
    client_opens: int  # times a client opened the pty (0 where that cannot be seen)
    wrong_baud: int  # times a client set a baud rate other than the device's
    peer_present: bool | None
    peer_seen: bool | None  # a client ever had the port open (None: cannot be seen)
    host_baud: int | None  # the client's baud rate where it can be seen (a pty)
    wrong_baud_rate: int | None  # the last wrong rate a client set (kept after it closed)
    dtr: bool | None
    device_mode: str | None
    pacing: PacingReport | None
    requests_by_command: dict[str, int]  # the device's well-formed requests, by name
    device_errors: dict[str, int]  # the device's protocol error counters that are not 0


def _no_return(sample: Any) -> Any:
    """The same angle, no reading: what a sensor reports where nothing echoed."""
    if dataclasses.is_dataclass(sample) and not isinstance(sample, type):
        return dataclasses.replace(sample, distance_mm=0.0, quality=0)
    return type(sample)(angle_deg=sample.angle_deg, distance_mm=0.0, quality=0)


def _drain(fd: int) -> None:
    try:
        while os.read(fd, 4096):
            pass
    except OSError:  # BlockingIOError: empty
        pass


class DeviceServer:
    """An emulated LIDAR `device` served on `port` by one background thread.

    Call ``start()`` (or use ``with``). Errors in the thread (a vanished
    port, a device bug) stop it; they are kept in ``error`` and raised as
    ``LinkError`` by the next ``send_revolution``/``wait_idle``/``close``.
    """

    def __init__(
        self,
        device: Any,
        port: DevicePort,
        *,
        mode: Mode = "lockstep",
        baudrate: int = 115200,
        revolution_period_s: float = 0.1,
        next_start: NextStart = "extra",
        bits_per_byte: int = 10,
        unit_samples: int | None = None,
        follow_dtr: bool = True,
        motor_on_when_dtr: bool = False,
        motor_on_without_dtr: bool = True,
        reset_s: float = 0.1,
        request_gap_s: float = 0.1,
        poll_s: float = 0.01,
        listener: Callable[[Any], None] | None = None,
        continuous: bool = False,
    ) -> None:
        if mode not in ("lockstep", "realtime"):
            raise ValueError(f"mode must be lockstep or realtime, not {mode!r}")
        if next_start not in ("extra", "replace"):
            raise ValueError(f"next_start must be extra or replace, not {next_start!r}")
        if revolution_period_s <= 0:
            raise ValueError("revolution_period_s must be positive")
        self.device = device
        self.port = port
        self.mode: Mode = mode
        self.baudrate = baudrate
        self.period_s = revolution_period_s
        self.next_start: NextStart = next_start
        self.follow_dtr = follow_dtr
        # The A1 dev kit: the rplidar package starts the motor with setDTR(False).
        self.motor_on_when_dtr = motor_on_when_dtr
        # A pty has no DTR to follow: the board's driver is taken to have started the motor.
        self.motor_on_without_dtr = motor_on_without_dtr
        self.reset_s = reset_s  # how long a RESET reboot lasts before the banner
        self.request_gap_s = request_gap_s  # line quiet this long: a partial request is dropped
        self.poll_s = poll_s
        self._unit_override = unit_samples
        # A whole run: never fall silent while the device scans (see the module docstring).
        self.continuous = continuous
        self.damage: Any = None  # a harness.faults.link.LineDamage, set before the run starts
        # Told (on the server thread) of line events and, through the device, of
        # each request and protocol error: what `emulate -v` prints.
        self.listener = listener
        if listener is not None and hasattr(device, "listener"):
            device.listener = listener
        self._encode = self._encoder(device)
        self._ld_style = "start_ms" in self._encode_params
        self.pacer = LinePacer(baudrate, bits_per_byte) if mode == "realtime" else None

        self._lock = threading.Lock()
        # samples, tick, period, push id
        self._inbox: deque[tuple[Sequence[Any], int, float, int]] = deque()
        self._idle = threading.Event()
        self._idle.set()
        self._changed = threading.Event()  # device state may have changed
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
        if port.paced_by_hardware:
            self._chunk = max(16, int(baudrate / bits_per_byte * _HARDWARE_CHUNK_S))
            self._budget = self._chunk
        else:
            self._chunk, self._budget = _LOCKSTEP_CHUNK, 16 * _LOCKSTEP_CHUNK

        # Owned by the server thread from start() on.
        self._reply = bytearray()
        self._stream = bytearray()
        self._rev_left = 0  # bytes of the current revolution (not its marker) still in _stream
        # The revolution being written: tick, first write time, push id, repeat?
        self._current: tuple[int, float | None, int | None, bool] | None = None
        self._write_ns = 0  # system time just before the last write to the port
        self._rev_lost = 0  # bytes of the current revolution the port did not take
        self._marker_sent = False  # a start marker stands in for the next revolution's start
        self._marker_size = 0  # samples in the last marker
        self._carry = 0  # samples a packetizing encoder holds for its next packet
        self._last_samples: Sequence[Any] | None = None
        self._last_tick = -1
        self._last_period = revolution_period_s
        self._marker_at = 0.0  # realtime: when the last underrun marker was queued
        self._push_count = 0  # ids of pushed revolutions
        # Continuous lockstep: between scenarios the last revolution streams every
        # period (harness thread sets and clears it under the lock).
        self._idling = False
        self._idle_due = 0.0
        self._idle_request: tuple[Sequence[Any], float] | None = None  # held samples, period
        self._idle_quiet = threading.Event()  # the thread saw the idle stream end
        self._whole_marker_pending = False  # end the stream on a whole start marker, first
        self._next_due: float | None = None  # realtime: nominal start of the next revolution
        self._was_streaming = self._streaming()
        self._dtr: bool | None = None
        self._dtr_polled = 0.0
        self._peer: bool | None = None  # the client has the port open (pty only)
        # Ptys tell whether a client has them open; a real UART cannot (None).
        self._peer_seen: bool | None = None if port.peer_present() is None else False
        self._peer_since = 0.0
        self._host_baud: int | None = None
        self._wrong_baud_rate: int | None = None
        self._motor_off_streak = False
        self._stalled = False
        self._session = getattr(device, "session", None)
        self._reboot_at: float | None = None
        self._last_rx: float | None = None  # host bytes since the line was last quiet
        self._t0 = 0.0
        self._deliveries: list[RevolutionSent] = []
        self._n = dict.fromkeys(
            (
                "bytes_written",
                "reply_bytes",
                "host_bytes",
                "host_reads",
                "revolutions_sent",
                "revolutions_dropped",
                "revolutions_superseded",
                "revolutions_repeated",
                "markers_sent",
                "stream_bytes_dropped",
                "overrun_bytes",
                "underruns",
                "revolutions_whole",
                "revolutions_cut",
                "motor_off_revolutions",
                "client_opens",
                "wrong_baud",
            ),
            0,
        )

    # ----------------------------------------------------------- harness side

    def start(self) -> DeviceServer:
        if self._started:
            raise RuntimeError("DeviceServer already started")
        self._started = True
        self._t0 = time.monotonic()
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
        return self._unit()

    @property
    def marker_samples(self) -> int:
        """Samples in the last start marker: what "replace" takes off the next revolution."""
        return self._marker_size

    def send_revolution(
        self, samples: Sequence[Any], tick: int, period_s: float | None = None
    ) -> int:
        """Queue one revolution; it goes out on the server thread. Returns its id
        (``delivery_of``).

        `period_s`: in real time, how long this revolution lasts before the
        next is due (a drifting rate); default the server's period. In
        continuous lockstep a push also ends the idle stream.
        """
        self._check()
        with self._lock:
            if self.mode == "realtime" and self._inbox:
                # A real sensor reports the present: a revolution still
                # waiting for its slot is replaced by the newer one.
                self._inbox.popleft()
                self._n["revolutions_superseded"] += 1
            self._push_count += 1
            self._inbox.append((list(samples), tick, period_s or self.period_s, self._push_count))
            self._idling = False
            self._idle.clear()
        self._wake()
        return self._push_count

    def stream_idle(
        self, samples: Sequence[Any] | None = None, period_s: float | None = None
    ) -> None:
        """Continuous: between scenarios, keep the device streaming until the next push.

        `samples` replaces the revolution to stream (default: the last one
        sent); in realtime it streams anyway once nothing new comes, in
        lockstep it goes out every `period_s` (default: the last period).
        """
        if not self.continuous:
            raise RuntimeError("stream_idle needs a continuous server")
        self._check()
        with self._lock:
            if samples is not None:
                self._idle_request = (list(samples), period_s or self.period_s)
            self._idling = self.mode == "lockstep"
        self._wake()

    def end_idle(self, timeout: float) -> RevolutionSent | None:
        """Continuous lockstep: stop the idle stream before the next push; wait (at most
        `timeout` s) until the revolution it was writing is out. Returns the last
        repeat written since the last push (its driver scan comes before the
        push's), or None.

        The stream then ends on a whole start marker (one packet of an LD06's,
        one node of an A1's), however many idle revolutions went out, so the
        bytes of the pushes that follow do not depend on how long the idle
        stream ran (same seed, same bytes, line damage included).
        """
        self._check()
        with self._lock:
            was = self._idling
            self._idling = False
            if not (was and self.mode == "lockstep"):
                return None
            self._whole_marker_pending = True
            self._idle_quiet.clear()
        self._wake()
        self._idle_quiet.wait(max(0.0, timeout))
        self._check()
        with self._lock:
            last = self._deliveries[-1] if self._deliveries else None
        return last if last is not None and last.repeat else None

    def align_stream(self) -> None:
        """Lockstep: end what was sent so far on a whole start marker before the next push,
        so the pushes that follow are the same bytes however many went before (a warm-up
        retried, say); see ``end_idle``."""
        self._check()
        with self._lock:
            self._whole_marker_pending = self.mode == "lockstep"
        self._wake()

    def delivery_of(self, push_id: int) -> RevolutionSent | None:
        """When the pushed revolution `push_id` went out whole, or None (not yet, or never)."""
        with self._lock:
            for delivery in reversed(self._deliveries):
                if delivery.push_id == push_id:
                    return delivery
                if delivery.push_id is not None and delivery.push_id < push_id:
                    return None
        return None

    def wait_idle(self, timeout: float) -> bool:
        """Wait (at most `timeout` s) until everything queued was written; False on timeout."""
        self._check()
        done = self._idle.wait(max(0.0, timeout))
        self._check()
        if done and not self._thread.is_alive() and self._started and not self._closed:
            raise LinkError("serial device server stopped")
        return done

    def wait_until(self, predicate: Callable[[Any], bool], timeout: float) -> bool:
        """Wait (at most `timeout` s) until `predicate(device)` holds, e.g. "scanning".

        Re-checked whenever the server thread has handled host bytes or a
        DTR change, and every 50 ms; reading device state from here is safe
        for simple attributes (``mode``, ``motor_on``).
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
            return list(self._deliveries)

    def stats(self) -> ServerStats:
        with self._lock:
            pacing = self.pacer.report(self.period_s) if self.pacer is not None else None
            counts = dict(self._n)
        try:
            peer = self.port.peer_present() if not self._closed else None
        except LinkError:
            peer = None
        mode = getattr(self.device, "mode", None)
        counters = getattr(self.device, "counters", None)
        counters = dict(counters) if isinstance(counters, dict) else {}
        requests = counters.pop("requests", None)
        by_command = getattr(self.device, "requests_by_command", None)
        return ServerStats(
            mode=self.mode,
            requests_seen=requests,
            peer_present=peer,
            peer_seen=self._peer_seen,
            host_baud=self._host_baud,
            wrong_baud_rate=self._wrong_baud_rate,
            dtr=self._dtr,
            device_mode=mode if isinstance(mode, str) else None,
            pacing=pacing,
            requests_by_command=dict(by_command) if isinstance(by_command, dict) else {},
            device_errors={k: v for k, v in counters.items() if v},
            **counts,
        )

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
        alive = self._thread.is_alive()
        if not alive:
            os.close(self._wake_r)
            os.close(self._wake_w)
        if alive:
            raise LinkError(f"serial device server did not stop within {timeout:g} s")
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
        try:
            os.write(self._wake_w, b"w")
        except OSError:  # full (a wake-up is pending anyway) or closed
            pass

    # ------------------------------------------------------------ device glue

    def _encoder(self, device: Any) -> Callable[[Sequence[Any], int], bytes]:
        encode = device.encode_revolution
        try:
            self._encode_params = set(inspect.signature(encode).parameters)
        except (TypeError, ValueError):
            self._encode_params = set()
        if "start_ms" in self._encode_params:
            return lambda samples, ms: encode(list(samples), start_ms=ms)
        return lambda samples, ms: encode(list(samples))

    def _unit(self) -> int:
        if self._unit_override:
            return self._unit_override
        n = getattr(self.device, "samples_per_packet", None)
        if isinstance(n, int) and n > 0:
            return n
        return 12 if self._ld_style else 1

    def _streaming(self) -> bool:
        return getattr(self.device, "mode", "scan") != "idle"

    def _stamp_ms(self, tick: int, now: float) -> int:
        """Device timestamps: from the tick in lockstep (same bytes every run), else the clock."""
        if self.mode == "lockstep":
            return round(tick * self.period_s * 1000.0)
        return round((now - self._t0) * 1000.0)

    # ------------------------------------------------------------- the thread

    def _run(self) -> None:
        try:
            if self.mode == "realtime":
                self.realtime_priority = raise_to_realtime()
            set_motor = getattr(self.device, "set_motor", None)
            if set_motor is not None and self.motor_on_without_dtr:
                if not self.follow_dtr or self.port.dtr_asserted() is None:
                    set_motor(True)
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
            self._idle.set()
            self._changed.set()

    def _step(self) -> None:
        now = time.monotonic()
        self._poll_dtr(now)
        self._housekeeping(now)
        self._next_revolution(now)
        data = self.port.read(4096, self._read_timeout(time.monotonic()), self._wake_r)
        _drain(self._wake_r)
        if data:
            self._on_host_bytes(data)
        now = time.monotonic()
        self._next_revolution(now)
        self._write(now)
        with self._lock:
            if not (self._inbox or self._reply or self._stream):
                self._idle.set()

    def _read_timeout(self, now: float) -> float:
        if self._reply or self._stream:
            if self.pacer is not None:
                return min(self.poll_s, max(0.0, self.pacer.due(now) - now))
            # lockstep: more to write at once, or the port took less than
            # offered: retry soon, or slowly while nobody has the other end open.
            if not self._stalled:
                return 0.0
            return self.poll_s if self.port.peer_present() is False else min(self.poll_s, 0.002)
        if self.mode == "realtime" and self._next_due is not None:
            underrun_due = self._last_samples is not None and not self._marker_sent
            if self._inbox or underrun_due:
                return min(self.poll_s, max(0.0, self._next_due - now))
            if self.continuous and self._last_samples is not None:
                return min(self.poll_s, max(0.0, self._repeat_due() - now))
        if self._idling:
            return min(self.poll_s, max(0.0, self._idle_due - now))
        return self.poll_s

    def _housekeeping(self, now: float) -> None:
        """The device's timed events: the end of a RESET reboot, a request cut short."""
        if self._reboot_at is not None and now >= self._reboot_at:
            self._reboot_at = None
            finish = getattr(self.device, "finish_reset", None)
            if finish is not None:
                self._add_reply(finish())
        if self._last_rx is not None and now - self._last_rx >= self.request_gap_s:
            self._last_rx = None
            drop = getattr(self.device, "drop_partial_request", None)
            if drop is not None:
                drop()

    def _add_reply(self, reply: bytes) -> None:
        if reply:
            self._stalled = False  # new bytes: try the port at once
            self._reply += reply
            self._n["reply_bytes"] += len(reply)

    def _tell(self, event: Any) -> None:
        if self.listener is not None:
            self.listener(event)

    def _poll_dtr(self, now: float, *, force: bool = False) -> None:
        if not force and now - self._dtr_polled < _DTR_POLL_S:
            return
        self._dtr_polled = now
        self._poll_peer(now)
        if not self.follow_dtr:
            return
        dtr = self.port.dtr_asserted()
        if dtr is None or dtr == self._dtr:
            return
        self._dtr = dtr
        set_motor = getattr(self.device, "set_motor", None)
        if set_motor is not None:
            on = dtr if self.motor_on_when_dtr else not dtr
            set_motor(on)
            self._changed.set()
            line = "asserted" if dtr else "deasserted"
            self._tell(LineEvent("motor", f"board's DTR {line}: motor {'on' if on else 'off'}"))

    def _poll_peer(self, now: float) -> None:
        """Whether a client has the port open, and at which baud (ptys tell both)."""
        peer = self.port.peer_present()
        if peer is None:
            return
        if self._peer_seen is None:
            self._peer_seen = False
        if peer != self._peer:
            self._peer = peer
            if peer:
                self._peer_seen = True
                self._peer_since = now
                self._n["client_opens"] += 1
                self._tell(LineEvent("client_opened", f"a client opened {self.port.name}"))
            elif self._peer_seen:
                self._host_baud = None
                self._tell(LineEvent("client_closed", f"the client closed {self.port.name}"))
        if not peer or now - self._peer_since < _BAUD_SETTLE_S:
            return
        baud = self.port.host_baud()
        if baud is None or baud == self._host_baud:
            return
        self._host_baud = baud
        if baud != self.baudrate:
            self._n["wrong_baud"] += 1
            self._wrong_baud_rate = baud
            self._tell(
                LineEvent(
                    "wrong_baud",
                    f"the client set its line to {baud} baud; this device talks at "
                    f"{self.baudrate} (a pty carries the bytes anyway, a real cable "
                    "would garble them)",
                )
            )
        else:
            self._tell(LineEvent("baud_ok", f"the client's line is at {baud} baud"))

    def _on_host_bytes(self, data: bytes) -> None:
        # A modem line set before these bytes were written (setDTR, then a
        # request) is seen first, as on a wire; so is "a client opened".
        self._poll_dtr(time.monotonic(), force=True)
        self._n["host_bytes"] += len(data)
        self._n["host_reads"] += 1
        receive = getattr(self.device, "receive", None)
        if receive is None:  # stream-only device: host bytes go nowhere
            return
        self._last_rx = time.monotonic()
        reply = receive(bytes(data))
        self._changed.set()
        self._add_reply(reply)
        if getattr(self.device, "rebooting", False) and self._reboot_at is None:
            self._reboot_at = time.monotonic() + self.reset_s
        streaming = self._streaming()
        session = getattr(self.device, "session", None)
        if session is not None:
            over = session != self._session  # the device started or ended a scan
        else:
            over = bool(reply) or streaming != self._was_streaming
        self._session, self._was_streaming = session, streaming
        if over:
            # What the device was streaming is over: unsent bytes of it would
            # corrupt the replies that follow, and a new scan starts afresh.
            if self._current is not None:
                self._n["revolutions_cut"] += 1
            self._n["stream_bytes_dropped"] += len(self._stream)
            self._stream.clear()
            self._rev_left = 0
            self._current = None
            self._marker_sent = False
            self._next_due = None

    def _next_revolution(self, now: float) -> None:
        if self._stream:
            return
        with self._lock:  # a whole marker asked for goes before anything pushed after it
            whole, self._whole_marker_pending = self._whole_marker_pending, False
            due = self.mode == "lockstep" or self._next_due is None or now >= self._next_due
            item = self._inbox.popleft() if self._inbox and due else None
            request, self._idle_request = self._idle_request, None
            idling = self._idling
        if whole:
            self._whole_marker(now)
            self._idle_quiet.set()
        if request is not None:  # the revolution to stream while nothing new comes
            self._last_samples, self._last_period = request
            if idling:
                self._idle_due = now
        if item is not None:
            samples, tick, period, push_id = item
            self._begin(samples, tick, period, now, push_id=push_id)
        elif self.mode == "realtime":
            if due:
                self._realtime_gap(now)
        elif idling and now >= self._idle_due:
            self._idle_due = now + self._last_period
            self._repeat(now)

    def _realtime_gap(self, now: float) -> None:
        """Realtime, a slot with nothing new: close the last revolution (its start
        marker); continuous, if still nothing after half a period, send it again."""
        if self._last_samples is None:
            return
        if self._next_due is None:  # a fresh scan: no revolution of it to close yet
            if self.continuous:
                self._repeat(now)
            return
        if not self._marker_sent:
            self._n["underruns"] += 1
            self._append_marker(self._last_samples, self._last_tick + 1, now)
            self._marker_at = now
        elif self.continuous and now >= self._repeat_due():
            self._repeat(now)

    def _repeat_due(self) -> float:
        """Continuous realtime: when the last revolution goes out again, nothing new having
        come (half a period after the marker that closed it; at once after a fresh SCAN)."""
        if self._next_due is None:
            return 0.0
        if not self._marker_sent:
            return self._next_due
        return self._marker_at + self._last_period / 2

    def _whole_marker(self, now: float) -> None:
        """End the stream on a start marker of a whole unit (see ``end_idle``)."""
        if self._last_samples is None or not self._streaming():
            return
        if not self._marker_sent or self._marker_size != self._unit():
            self._append_marker(self._last_samples, self._last_tick + 1, now)

    def _repeat(self, now: float) -> None:
        """Send the last revolution again (the device keeps scanning the same world)."""
        if self._last_samples is None or not self._streaming():
            return
        self._n["revolutions_repeated"] += 1
        self._begin(self._last_samples, self._last_tick, self._last_period, now, repeat=True)

    def _begin(
        self,
        samples: Sequence[Any],
        tick: int,
        period: float,
        now: float,
        *,
        push_id: int | None = None,
        repeat: bool = False,
    ) -> None:
        ms = self._stamp_ms(tick, now)
        skip = self._marker_size if self._marker_sent and self.next_start == "replace" else 0
        if self._ld_style:
            # Packets carry no start flag and the encoder keeps a partial
            # packet between calls: "replace" leaves the marker's samples out.
            data = self._encode_counted(samples[skip:], ms)
        else:
            data = self._encode(samples, ms)
            if skip:  # stateless nodes: drop the replaced nodes' bytes (and the start flag)
                data = data[len(self._encode(samples[:skip], ms)) :]
        if self.damage is not None:  # line faults: the bytes as the far end gets them
            data = self.damage.damage(data)
        if not data:
            self._n["revolutions_dropped"] += 1
            self._note_motor_off()
            return
        self._motor_off_streak = False
        self._marker_sent = False
        self._stalled = False  # new bytes: try the port at once
        self._stream += data
        self._rev_left = len(data)
        self._rev_lost = 0
        self._current = (tick, None, push_id, repeat)
        self._last_samples, self._last_tick, self._last_period = samples, tick, period
        self._n["revolutions_sent"] += 1
        if self.mode == "realtime":
            nominal = self._next_due if self._next_due is not None else now
            if now - nominal > period:  # more than a period late: a new schedule
                nominal = now
            self._next_due = nominal + period
        else:
            self._append_marker(samples, tick + 1, now)

    def _note_motor_off(self) -> None:
        """A scan was asked for but nothing streams: the motor is off. Said once a streak."""
        if getattr(self.device, "mode", "idle") == "idle":
            return
        if getattr(self.device, "motor_on", True):
            return
        self._n["motor_off_revolutions"] += 1
        if not self._motor_off_streak:
            self._motor_off_streak = True
            self._tell(
                LineEvent(
                    "motor_off",
                    "a scan was asked for but the motor is off (the board's DTR asserted, "
                    "or MOTOR_PWM 0): an A1 streams nothing until it turns",
                )
            )

    def _encode_counted(self, samples: Sequence[Any], ms: int) -> bytes:
        """Encode with a packetizing encoder, tracking the samples it holds back."""
        self._carry = (self._carry + len(samples)) % self._unit()
        return self._encode(samples, ms)

    def _append_marker(self, samples: Sequence[Any], tick: int, now: float) -> None:
        if getattr(self.device, "mode", None) == "express":
            # Express capsules carry no start flag and the encoder holds back
            # samples until the next capsule starts: a marker would mix into
            # the next revolution's capsules. No marker (see docs/serial.md).
            return
        # Complete the packet the encoder holds open, or send one whole unit:
        # either way the next revolution starts on a packet boundary, so no
        # packet mixes the marker's angles with the next sweep's.
        unit = self._unit()
        size = unit - self._carry if self._carry else unit
        head = [_no_return(s) for s in samples[:size]]
        if not head:
            return
        ms = self._stamp_ms(tick, now)
        marker = self._encode_counted(head, ms) if self._ld_style else self._encode(head, ms)
        if marker:
            self._stream += marker
            self._marker_sent = True
            self._marker_size = len(head)
            self._n["markers_sent"] += 1

    def _write(self, now: float) -> None:
        if self.pacer is None:
            budget = self._budget  # then look at the host again
            while budget > 0 and (self._reply or self._stream):
                buf = self._reply or self._stream
                chunk = bytes(buf[: self._chunk])
                self._write_ns = time.time_ns()
                n = self.port.write(chunk, 0.0)
                self._consumed(buf, n, n, time.monotonic())
                budget -= len(chunk)
                self._stalled = n < len(chunk)
                if self._stalled:
                    return
            return
        while self._reply or self._stream:
            buf = self._reply or self._stream
            n = self.pacer.allowance(len(buf), now)
            if n == 0:
                return
            self._write_ns = time.time_ns()
            written = self.port.write(bytes(buf[:n]), 0.0)
            with self._lock:
                if buf is self._stream and self._current is not None and self._current[1] is None:
                    self.pacer.mark_revolution(now)
                self.pacer.sent(n, now)
            # Line time passed either way: what the port did not take is lost,
            # as on a UART whose receiver is not reading.
            self._n["overrun_bytes"] += n - written
            self._consumed(buf, n, written, now)
            now = time.monotonic()

    def _consumed(self, buf: bytearray, n: int, written: int, now: float) -> None:
        """`n` bytes leave `buf` (`written` of them reached the port) at `now`."""
        if n <= 0:
            return
        del buf[:n]
        self._n["bytes_written"] += written
        if buf is not self._stream or self._current is None:
            return
        tick, started, push_id, repeat = self._current
        if started is None:
            started = now
            self._current = (tick, now, push_id, repeat)
        self._rev_left -= n
        self._rev_lost += n - written
        if self._rev_left <= 0:
            if not self._rev_lost:
                self._n["revolutions_whole"] += 1
            with self._lock:
                self._deliveries.append(
                    RevolutionSent(tick, started, now, push_id, self._write_ns, repeat)
                )
            self._current = None
            self._rev_left = 0
