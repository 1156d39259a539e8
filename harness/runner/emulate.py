"""`fossbot-hil emulate`: serve a scenario's scans as a LIDAR device on a port.

For users testing their own drivers: the harness is the device, in real
time, with no ROS. Without a port a pty stands in for the cable: its path
is printed first, then the environment under which a pyserial client's
DTR/RTS calls reach the emulator. It explains itself (every event with
``verbose``, else a status line every few seconds), and Ctrl-C ends it with
the same summary as the scenario's end.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from harness.devices.profiles import DeviceProfile
from harness.errors import ConfigError, Interrupted
from harness.faults.link import LINE_KINDS, LineDamage, LinkFaults
from harness.lidar.mount import FORWARD, LidarMount
from harness.links.base import LinkOptions
from harness.runner.plan import plan_one
from harness.runner.settings import RunSettings
from harness.scenario.schema import Scenario
from harness.serial_line.diagnosis import counts_text, diagnose, line_errors

IDLE_WAIT_S = 5.0  # after the last revolution: let the line drain
STATUS_EVERY_S = 5.0  # without verbose: one status line this often
# The line after "port: ..." on a pty: what a client's shell needs for DTR/RTS.
MODEM_LINES_PREFIX = "modem lines: "


@dataclass(frozen=True)
class EmulationSummary:
    """What was served, for the closing lines and for tests."""

    revolutions: int  # simulated
    bytes_written: int
    mean_rate_error_pct: float | None
    port: str = ""
    elapsed_s: float = 0.0
    stopped_by: str | None = None  # "SIGINT" / "SIGTERM"; None: the scenario ended
    revolutions_whole: int = 0  # every byte written
    revolutions_cut: int = 0  # a request (STOP, another SCAN) cut off the rest
    revolutions_idle: int = 0  # the device encoded nothing: not scanning, or motor off
    reply_bytes: int = 0
    host_bytes: int = 0
    requests_by_command: dict[str, int] = field(default_factory=dict)
    errors: dict[str, int] = field(default_factory=dict)  # protocol and line errors, by name
    client_seen: bool | None = None  # a client opened the port (None: cannot be seen)
    likely: str = ""  # the likely cause when nothing was read

    @property
    def client_read(self) -> bool | None:
        """Did a client read anything? None where a real line cannot tell (a stream to a UART)."""
        if self.client_seen is not None:
            return self.client_seen and self.bytes_written > 0
        if self.requests_by_command:
            return self.bytes_written > 0
        return None if self.bytes_written else False

    def lines(self) -> list[str]:
        """The summary as printed: a headline that never reads like success when it was not."""
        how = f"stopped by {self.stopped_by}" if self.stopped_by else "scenario ended"
        head = f"{how} after {self.elapsed_s:.1f} s: "
        if self.client_seen is False:
            head += (
                f"NO CLIENT: nothing opened {self.port}; {self.revolutions} revolutions "
                "simulated, none served"
            )
        elif self.client_read is False:
            head += f"NOTHING SERVED: no client read anything on {self.port}"
        elif self.revolutions_whole == 0 and self.revolutions_cut == 0:
            head += f"NO SCAN SERVED: the client on {self.port} never received a revolution"
        else:
            head += f"served {self.revolutions_whole} whole revolutions on {self.port}"
        rate = self.mean_rate_error_pct
        lines = [
            head,
            "  requests: " + counts_text(self.requests_by_command),
            f"  revolutions: {self.revolutions} simulated, {self.revolutions_whole} served whole, "
            f"{self.revolutions_cut} cut short by a request, "
            f"{self.revolutions_idle} found the device idle",
            f"  bytes: {self.bytes_written} to the client ({self.reply_bytes} in answers), "
            f"{self.host_bytes} from it"
            + (f"; line rate error {rate:+.2f} %" if rate is not None else ""),
            "  errors: " + counts_text(self.errors),
            "  client: " + _client_text(self),
        ]
        if self.likely and not (self.revolutions_whole or self.revolutions_cut):
            lines.append(f"  likely cause: {self.likely}")
        return lines


def _client_text(summary: EmulationSummary) -> str:
    read = summary.client_read
    if read is None:
        return "unknown (a real line cannot tell whether anything read the stream)"
    if summary.client_seen is False:
        return "never connected"
    return "read from the device" if read else "never read"


def check_device_faults(faults: LinkFaults) -> None:
    """A device on a line can drift and have its bytes damaged; the rest is not its doing."""
    other = [f.kind for f in faults.items if f.kind != "rate_drift" and f.kind not in LINE_KINDS]
    if other:
        raise ConfigError(
            f"faults {', '.join(other)}: emulate plays a LIDAR device, which cannot "
            "drop, repeat, reorder, delay or restamp the board's scans (rate_drift and "
            "line faults apply)"
        )


class _Log:
    """Lines for the user from two threads (the server's events, the loop's status)."""

    def __init__(self, write: Callable[[str], None], started: float, verbose: bool) -> None:
        self._write, self._started, self.verbose = write, started, verbose
        self._lock = threading.Lock()
        self._errors_seen: set[str] = set()

    def line(self, text: str) -> None:
        with self._lock:
            self._write(f"[{time.monotonic() - self._started:7.2f} s] {text}")

    def event(self, event: Any) -> None:
        """A device or line event: every one with verbose, else each kind of error once."""
        if self.verbose:
            self.line(event.text())
        elif event.is_error and event.kind not in self._errors_seen:
            self._errors_seen.add(event.kind)
            self.line(f"{event.text()} [first of its kind; -v logs every one]")


def _rts_reporter(log: _Log) -> Callable[[str, bool], None]:
    """The client's RTS changes as line events (its DTR is the server's: the motor)."""
    from harness.serial_line.line_watch import LineEvent

    def told(line: str, asserted: bool) -> None:
        if line == "rts":
            state = "asserted" if asserted else "deasserted"
            log.event(LineEvent("rts", f"the client's RTS {state}"))

    return told


# The device's mode as the status line says it ("scan": SCAN or FORCE_SCAN), else
# "scanning (MODE)".
_STATES = {"idle": "idle", "scan": "scanning (standard)", "streaming": "streaming"}


def status_line(stats: Any) -> str:
    """One line on the state of the line: the client, scanning or idle, what was served."""
    if stats.peer_present is None:
        client = "client: cannot be seen on a real port"
        if stats.host_bytes:
            client += f" ({stats.host_bytes} bytes from it)"
    elif stats.peer_present:
        baud = f" at {stats.host_baud} baud" if stats.host_baud else ""
        client = f"client: connected{baud}"
    else:
        client = "client: none" + (" (one came and went)" if stats.peer_seen else "")
    mode = stats.device_mode or "streaming"  # a device without modes streams unasked
    state = _STATES.get(mode, f"scanning ({mode})")
    errors = sum(stats.device_errors.values()) + stats.wrong_baud + stats.motor_off_revolutions
    return (
        f"{client} | {state} | {stats.revolutions_sent} revolutions, "
        f"{stats.bytes_written} bytes served | requests {stats.requests_seen or 0} | "
        f"errors {errors}"
    )


def emulate(
    profile: DeviceProfile,
    scenario: Scenario,
    *,
    port: str | None = None,
    settings: RunSettings | None = None,
    announce: Callable[[str], None] = print,
    verbose: bool = False,
    mount: LidarMount = FORWARD,
) -> EmulationSummary:
    """Serve every revolution of `scenario` in real time until it ends or Ctrl-C stops it."""
    settings = settings or RunSettings()
    from harness.serial_line.device_line import open_device_line
    from harness.serial_line.ports import PtyPort
    from harness.sim.simulation import Simulation

    spec = scenario.lidar_spec
    plan = plan_one(scenario, profile.name, LinkOptions(), settings)  # a mistake opens nothing
    check_device_faults(plan.profile.link)
    started = time.monotonic()
    log = _Log(announce, started, verbose)
    damage = LineDamage(plan.profile.link, plan.seed) if plan.profile.link.on_line else None
    device = profile.make_device(spec.rate_hz)
    device_line = open_device_line(
        device,
        port=port or None,
        baudrate=profile.baudrate,
        mode="realtime",
        revolution_period_s=spec.scan_time,
        listener=log.event,
        damage=damage,
    )
    line, server, name = device_line.port, device_line.server, device_line.name
    rng = np.random.default_rng(plan.seed)
    revolutions = 0
    stopped_by: str | None = None
    try:
        announce(f"port: {name}")  # from here on, a stop is a normal end
        if isinstance(line, PtyPort):
            announce(f"{MODEM_LINES_PREFIX}{line.client_exports()}")
            line.on_modem_change = _rts_reporter(log)
        # The simulation first: building it silences stdout (fd 1) for a moment,
        # which would swallow what the server thread logs meanwhile.
        with Simulation(scenario) as sim, server:
            status_due = started + STATUS_EVERY_S
            for tick in sim.ticks(plan.periods()):
                due = started + tick.t
                while (left := due - time.monotonic()) > 0:
                    time.sleep(min(left, 0.05))  # pacing the scenario clock, not syncing
                    server.wait_idle(0)  # surfaces a vanished port promptly
                    if time.monotonic() >= status_due:
                        log.line(status_line(server.stats()))
                        status_due += STATUS_EVERY_S
                scan = plan.profile.emit(tick.truth, spec, rng, stamp=tick.t)
                rate_hz = 1.0 / tick.period
                samples = profile.revolution(device, scan, rate_hz, spec.range_max, mount=mount)
                revolutions += 1  # first: a stop may come inside send_revolution
                server.send_revolution(samples, tick.tick, tick.period)
            server.wait_idle(IDLE_WAIT_S)
    except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM: a normal end, with its summary
        stopped_by = Interrupted.of(err).name
    finally:
        line.close()
    stats = server.stats()  # the thread has stopped: the counts are final
    unasked = profile.streams_unasked
    report = diagnose(stats, port=name, baudrate=profile.baudrate, streams_unasked=unasked)
    return EmulationSummary(
        revolutions=revolutions,
        bytes_written=stats.bytes_written,
        mean_rate_error_pct=stats.pacing.mean_rate_error_pct if stats.pacing else None,
        port=name,
        elapsed_s=time.monotonic() - started,
        stopped_by=stopped_by,
        revolutions_whole=stats.revolutions_whole,
        revolutions_cut=stats.revolutions_cut,
        revolutions_idle=stats.revolutions_dropped,
        reply_bytes=stats.reply_bytes,
        host_bytes=stats.host_bytes,
        requests_by_command=stats.requests_by_command,
        errors=line_errors(stats),
        client_seen=stats.peer_seen,
        likely=report.likely,
    )
