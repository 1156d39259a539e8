"""What a device server counted: the running counts, and the snapshot callers read.

Each part counts into one ``ServerCounts``; ``snapshot`` joins them with the
device's own counters into the ``ServerStats`` that `emulate`, the HIL link
and ``diagnosis`` read. Pure.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from harness.serial_line.pacing import PacingReport

if TYPE_CHECKING:  # serial_line sits below devices: the interface is only named here
    from harness.devices.protocol import LineDevice

__all__ = ["RevolutionSent", "ServerCounts", "ServerStats", "snapshot"]


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


@dataclass
class ServerCounts:
    """The running counts of one server run (the server thread writes them)."""

    bytes_written: int = 0
    reply_bytes: int = 0
    host_bytes: int = 0  # bytes the board sent us
    host_reads: int = 0  # reads that brought host bytes (fed to device.receive)
    revolutions_sent: int = 0
    revolutions_dropped: int = 0  # the device encoded nothing (not scanning)
    revolutions_superseded: int = 0  # realtime: replaced by a newer one before their slot
    revolutions_repeated: int = 0  # continuous: the last revolution sent again
    markers_sent: int = 0
    stream_bytes_dropped: int = 0  # unsent revolution bytes dropped when the device stopped
    overrun_bytes: int = 0  # realtime: bytes the line "sent" that the port did not take
    underruns: int = 0  # realtime: the next revolution was late at its slot
    revolutions_whole: int = 0  # revolutions whose every byte the port took
    revolutions_cut: int = 0  # revolutions whose remaining bytes a request (e.g. STOP) cut off
    motor_off_revolutions: int = 0  # scanning was asked for, but the motor was off
    client_opens: int = 0  # times a client opened the pty (0 where that cannot be seen)
    wrong_baud: int = 0  # times a client set a baud rate other than the device's


@dataclass(kw_only=True)
class ServerStats(ServerCounts):
    """A snapshot of one server run: counts, line state, device counters (pacing: realtime only)."""

    mode: str
    requests_seen: int | None  # well-formed requests, where the device counts them
    peer_present: bool | None
    peer_seen: bool | None  # a client ever had the port open (None: cannot be seen)
    host_baud: int | None  # the client's baud rate where it can be seen (a pty)
    wrong_baud_rate: int | None  # the last wrong rate a client set (kept after it closed)
    dtr: bool | None
    device_mode: str | None
    pacing: PacingReport | None
    requests_by_command: dict[str, int]  # the device's well-formed requests, by name
    device_errors: dict[str, int]  # the device's protocol error counters that are not 0


@dataclass(frozen=True)
class LineState:
    """What the line watch saw of the client: ``ServerStats``'s line fields."""

    peer_present: bool | None
    peer_seen: bool | None
    host_baud: int | None
    wrong_baud_rate: int | None
    dtr: bool | None


def snapshot(
    mode: str,
    counts: ServerCounts,
    line: LineState,
    device: LineDevice,
    pacing: PacingReport | None,
) -> ServerStats:
    """The server's counts, the line's state and the device's own counters, as one record."""
    counters = dict(device.counters)
    requests = counters.pop("requests", None)
    return ServerStats(
        mode=mode,
        requests_seen=requests,
        device_mode=device.mode,
        pacing=pacing,
        requests_by_command=dict(device.requests_by_command),
        device_errors={k: v for k, v in counters.items() if v},
        **asdict(line),
        **asdict(counts),
    )
