"""What a LIDAR streams next, tick by tick: revolutions, start markers, repeats, idle.

Pure: the server thread calls ``StreamPolicy`` with the time and what the
harness pushed, and takes the bytes it queued (``stream``); no thread, port
or clock of its own, so tests drive it with a fake clock and a real codec.

Start markers: a driver publishes revolution k only when k+1 starts, and in
lockstep the harness sends k+1 only after k's answers; so after every
revolution a start marker (the sweep's first angles, no return, one RPLIDAR
node or the rest of an LD06 packet) goes out, and ``next_start`` says whether
k+1 is then sent whole (``"extra"``) or without the ``marker_samples`` the
marker stood in for (``"replace"``): docs/serial.md, "The start of the next
revolution", says which drivers need which. The bytes stay a pure function
of the pushes. In realtime the marker goes out only on an underrun; express
scans get none (no start flag).

``continuous``: a real device streams from SCAN to STOP whatever the host
does, and a driver may wait for bytes with no timeout (rplidar-roboticia).
So in realtime a late slot gets the marker and, if nothing came within half
a period, the last revolution again (a *repeat*), each period; in lockstep,
between scenarios (``stream_idle``, until the next push or ``end_idle``),
the last revolution goes out every period. ``stream_idle(samples)`` sets
what to stream before any push. Repeats are marked in ``deliveries()``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Literal

from harness.serial_line.line_watch import LineEvent
from harness.serial_line.stats import RevolutionSent, ServerCounts

if TYPE_CHECKING:
    from harness.devices.protocol import LineDevice

__all__ = ["Mode", "NextStart", "Push", "StreamPolicy"]

Mode = Literal["lockstep", "realtime"]
NextStart = Literal["extra", "replace"]
# A pushed revolution: samples, tick, period, push id.
Push = tuple[Sequence[Any], int, float, int]
MOTOR_OFF = (
    "a scan was asked for but the motor is off (the board's DTR asserted, or MOTOR_PWM 0): "
    "an A1 streams nothing until it turns"
)


def no_return(sample: Any) -> Any:
    """The same angle, no reading: what a sensor reports where nothing echoed."""
    if dataclasses.is_dataclass(sample) and not isinstance(sample, type):
        return dataclasses.replace(sample, distance_mm=0.0, quality=0)
    return type(sample)(angle_deg=sample.angle_deg, distance_mm=0.0, quality=0)


class StreamPolicy:
    """The stream of one device: which revolution, marker or repeat goes out next.

    `damage` (a ``harness.faults.link.LineDamage``) spoils each revolution's
    bytes as the far end gets them; `tell` hears ``LineEvent``s
    (``motor_off``); `on_bytes` is called whenever a revolution's bytes are
    queued (the writer tries the port at once).
    """

    def __init__(
        self,
        device: LineDevice,
        counts: ServerCounts,
        *,
        mode: Mode = "lockstep",
        period_s: float = 0.1,
        next_start: NextStart = "extra",
        continuous: bool = False,
        tell: Callable[[Any], None] = lambda event: None,
        on_bytes: Callable[[], None] = lambda: None,
    ) -> None:
        if mode not in ("lockstep", "realtime"):
            raise ValueError(f"mode must be lockstep or realtime, not {mode!r}")
        if next_start not in ("extra", "replace"):
            raise ValueError(f"next_start must be extra or replace, not {next_start!r}")
        if period_s <= 0:
            raise ValueError("revolution_period_s must be positive")
        self.device, self.counts = device, counts
        self.mode: Mode = mode
        self.period_s = period_s
        self.next_start: NextStart = next_start
        self.continuous = continuous
        self.damage: Any = None
        self.t0 = 0.0  # device timestamps count from here in realtime
        self._tell, self._on_bytes = tell, on_bytes
        self.stream = bytearray()  # queued bytes, taken by the writer (``consumed``)
        self._rev_left = 0  # bytes of the current revolution (not its marker) still in stream
        # The revolution being written: tick, first write time, push id, repeat?
        self._current: tuple[int, float | None, int | None, bool] | None = None
        self._rev_lost = 0  # bytes of the current revolution the port did not take
        self.marker_sent = False  # a start marker stands in for the next revolution's start
        self.marker_size = 0  # samples in the last marker
        self._carry = 0  # samples a packetizing encoder holds for its next packet
        self._last_samples: Sequence[Any] | None = None
        self._last_tick = -1
        self._last_period = period_s
        self._marker_at = 0.0  # realtime: when the last underrun marker was queued
        self._next_due: float | None = None  # realtime: nominal start of the next revolution
        self._idle_due = 0.0  # continuous lockstep: when the idle stream repeats next
        self._motor_off_streak = False
        self._session = device.session

    @property
    def unit(self) -> int:
        """Samples in one packet of the device's stream (1 for RPLIDAR nodes)."""
        return self.device.samples_per_packet

    @property
    def streaming(self) -> bool:
        return self.device.mode != "idle"

    @property
    def writing_start(self) -> bool:
        """The next stream byte is the first of a revolution (the pacer marks it)."""
        return self._current is not None and self._current[1] is None

    def slot_open(self, now: float) -> bool:
        """May a pushed revolution begin now? In realtime only at its slot."""
        return self.mode == "lockstep" or self._next_due is None or now >= self._next_due

    # -- ticks -------------------------------------------------------------

    def advance(
        self,
        now: float,
        push: Push | None,
        *,
        whole_marker: bool = False,
        idle_request: tuple[Sequence[Any], float] | None = None,
        idling: bool = False,
    ) -> None:
        """One tick with the stream empty: queue what goes out next.

        `push`: the pushed revolution due now (the caller took it only if
        ``slot_open``); `whole_marker`: end the stream on a whole start
        marker first (``DeviceServer.end_idle``); `idle_request`: the
        revolution (and period) to stream while nothing new comes;
        `idling`: continuous lockstep between scenarios.
        """
        if whole_marker:
            self._whole_marker(now)
        if idle_request is not None:
            self._last_samples, self._last_period = idle_request
            if idling:
                self._idle_due = now
        if push is not None:
            samples, tick, period, push_id = push
            self._begin(samples, tick, period, now, push_id=push_id)
        elif self.mode == "realtime":
            if self.slot_open(now):
                self._realtime_gap(now)
        elif idling and now >= self._idle_due:
            self._idle_due = now + self._last_period
            self._repeat(now)

    def next_action_at(self, now: float, *, pushed: bool, idling: bool) -> float | None:
        """With nothing queued: when the stream next needs the thread (None: not scheduled)."""
        if self.mode == "realtime" and self._next_due is not None:
            underrun_due = self._last_samples is not None and not self.marker_sent
            if pushed or underrun_due:
                return self._next_due
            if self.continuous and self._last_samples is not None:
                return self._repeat_due()
        if idling:
            return self._idle_due
        return None

    def device_changed(self) -> None:
        """After host bytes reached the device: a scan that started or ended makes the
        queued stream stale (it would corrupt the replies that follow)."""
        session = self.device.session
        if session == self._session:
            return
        self._session = session
        if self._current is not None:
            self.counts.revolutions_cut += 1
        self.counts.stream_bytes_dropped += len(self.stream)
        self.stream.clear()
        self._rev_left = 0
        self._current = None
        self.marker_sent = False
        self._next_due = None

    def consumed(self, n: int, written: int, now: float, write_ns: int) -> RevolutionSent | None:
        """`n` stream bytes left (`written` of them reached the port) at `now`, the write
        begun at system time `write_ns`. Returns the revolution they finished, if any."""
        if n <= 0:
            return None
        del self.stream[:n]
        if self._current is None:
            return None
        tick, started, push_id, repeat = self._current
        if started is None:
            started = now
            self._current = (tick, now, push_id, repeat)
        self._rev_left -= n
        self._rev_lost += n - written
        if self._rev_left > 0:
            return None
        if not self._rev_lost:
            self.counts.revolutions_whole += 1
        self._current = None
        self._rev_left = 0
        return RevolutionSent(tick, started, now, push_id, write_ns, repeat)

    # -- what goes out ------------------------------------------------------

    def _realtime_gap(self, now: float) -> None:
        """Realtime, a slot with nothing new: close the last revolution (its start
        marker); continuous, if still nothing after half a period, send it again."""
        if self._last_samples is None:
            return
        if self._next_due is None:  # a fresh scan: no revolution of it to close yet
            if self.continuous:
                self._repeat(now)
            return
        if not self.marker_sent:
            self.counts.underruns += 1
            self._append_marker(self._last_samples, self._last_tick + 1, now)
            self._marker_at = now
        elif self.continuous and now >= self._repeat_due():
            self._repeat(now)

    def _repeat_due(self) -> float:
        """Continuous realtime: when the last revolution goes out again, nothing new having
        come (half a period after the marker that closed it; at once after a fresh SCAN)."""
        if self._next_due is None:
            return 0.0
        if not self.marker_sent:
            return self._next_due
        return self._marker_at + self._last_period / 2

    def _whole_marker(self, now: float) -> None:
        """End the stream on a start marker of a whole unit (see ``end_idle``)."""
        if self._last_samples is None or not self.streaming:
            return
        if not self.marker_sent or self.marker_size != self.unit:
            self._append_marker(self._last_samples, self._last_tick + 1, now)

    def _repeat(self, now: float) -> None:
        """Send the last revolution again (the device keeps scanning the same world)."""
        if self._last_samples is None or not self.streaming:
            return
        self.counts.revolutions_repeated += 1
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
        skip = self.marker_size if self.marker_sent and self.next_start == "replace" else 0
        if self.device.packetized:
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
            self.counts.revolutions_dropped += 1
            self._note_motor_off()
            return
        self._motor_off_streak = False
        self.marker_sent = False
        self._on_bytes()
        self.stream += data
        self._rev_left = len(data)
        self._rev_lost = 0
        self._current = (tick, None, push_id, repeat)
        self._last_samples, self._last_tick, self._last_period = samples, tick, period
        self.counts.revolutions_sent += 1
        if self.mode == "realtime":
            nominal = self._next_due if self._next_due is not None else now
            if now - nominal > period:  # more than a period late: a new schedule
                nominal = now
            self._next_due = nominal + period
        else:
            self._append_marker(samples, tick + 1, now)

    def _note_motor_off(self) -> None:
        """A scan was asked for but nothing streams: the motor is off. Said once a streak."""
        if self.device.mode == "idle" or self.device.motor_on:
            return
        self.counts.motor_off_revolutions += 1
        if not self._motor_off_streak:
            self._motor_off_streak = True
            self._tell(LineEvent("motor_off", MOTOR_OFF))

    def _encode(self, samples: Sequence[Any], ms: int) -> bytes:
        return self.device.encode_revolution(list(samples), start_ms=ms)

    def _encode_counted(self, samples: Sequence[Any], ms: int) -> bytes:
        """Encode with a packetizing encoder, tracking the samples it holds back."""
        self._carry = (self._carry + len(samples)) % self.unit
        return self._encode(samples, ms)

    def _append_marker(self, samples: Sequence[Any], tick: int, now: float) -> None:
        if self.device.mode == "express":
            # Express capsules carry no start flag and the encoder holds back
            # samples until the next capsule starts: a marker would mix into
            # the next revolution's capsules. No marker (see docs/serial.md).
            return
        # Complete the packet the encoder holds open, or send one whole unit:
        # either way the next revolution starts on a packet boundary, so no
        # packet mixes the marker's angles with the next sweep's.
        unit = self.unit
        size = unit - self._carry if self._carry else unit
        head = [no_return(s) for s in samples[:size]]
        if not head:
            return
        ms = self._stamp_ms(tick, now)
        marker = (
            self._encode_counted(head, ms) if self.device.packetized else self._encode(head, ms)
        )
        if marker:
            self.stream += marker
            self.marker_sent = True
            self.marker_size = len(head)
            self.counts.markers_sent += 1

    def _stamp_ms(self, tick: int, now: float) -> int:
        """Device timestamps: from the tick in lockstep (same bytes every run), else the clock."""
        if self.mode == "lockstep":
            return round(tick * self.period_s * 1000.0)
        return round((now - self.t0) * 1000.0)
