"""Why a serial line did not work: what was sent, what came back, the likely cause.

From the far end the usual failures look alike ("the board publishes no
/scan"); the line's counters tell them apart (nothing opened the port, no
request, wrong baud, a request the device lacks, motor off, crossed wires).
Pure: counters in, text out.
"""

from __future__ import annotations

from dataclasses import dataclass

from harness.option_names import worded
from harness.serial_line.stats import ServerStats

SCAN_REQUESTS = ("SCAN", "FORCE_SCAN", "EXPRESS_SCAN")
# Requests that ask for something the emulated device may not have.
_LACKS = ("unknown_command", "unknown_conf", "unsupported_mode")
# A client at the other emulated LIDAR's rate most likely is that LIDAR's driver.
_OTHER_DEVICE_AT: dict[int | None, tuple[str, str]] = {
    230400: ("an LD06/LD19", "emulate ldlidar, {link} ldlidar"),
    115200: ("an RPLIDAR A1", "emulate rplidar, {link} rplidar"),
}


@dataclass(frozen=True)
class LineReport:
    """The line's story in three parts, each one short phrase."""

    sent: str
    came_back: str
    likely: str  # "" when nothing looks wrong

    def text(self) -> str:
        likely = f"; likely cause: {self.likely}" if self.likely else ""
        return f"sent {self.sent}; came back {self.came_back}{likely}"


def counts_text(counts: dict[str, int]) -> str:
    """``{"GET_INFO": 1, "SCAN": 2}`` as "GET_INFO 1, SCAN 2" (or "none")."""
    return ", ".join(f"{name} {n}" for name, n in counts.items() if n) or "none"


def line_errors(stats: ServerStats) -> dict[str, int]:
    """Every protocol and line error counted, by name, zeros left out."""
    line = {"wrong_baud": stats.wrong_baud, "motor_off_revolutions": stats.motor_off_revolutions}
    return {**stats.device_errors, **{k: v for k, v in line.items() if v}}


def diagnose(stats: ServerStats, *, port: str, baudrate: int, streams_unasked: bool) -> LineReport:
    """What the emulator sent, what the client sent, and the likeliest reason it failed."""
    sent = f"{stats.bytes_written} bytes ({stats.reply_bytes} in answers, "
    sent += f"{stats.revolutions_sent} revolutions)"
    if stats.host_bytes:
        back = f"{stats.host_bytes} bytes: requests {counts_text(stats.requests_by_command)}"
        errors = line_errors(stats)
        if errors:
            back += f", errors {counts_text(errors)}"
    else:
        back = "nothing (0 bytes)"
    return LineReport(sent, back, _likely(stats, port, baudrate, streams_unasked))


def _likely(stats: ServerStats, port: str, baudrate: int, streams_unasked: bool) -> str:
    errors = stats.device_errors
    asked = stats.requests_by_command
    if stats.peer_seen is False:
        return f"nothing opened {port}: point the driver (or client) at {port} and start it"
    if stats.wrong_baud:
        rate = stats.host_baud or stats.wrong_baud_rate
        other = _OTHER_DEVICE_AT.get(rate) if rate != baudrate else None
        if other is not None:
            return (
                f"the client's line is at {rate} baud, the device's at {baudrate}; {rate} is "
                f"{other[0]}'s rate: a driver for {other[0]}? use its own device type "
                f"({worded(other[1])}), or set the driver's baud rate to {baudrate}"
            )
        return (
            f"the client's line is at {rate or 'another'} baud, the device's at "
            f"{baudrate}: set the driver's baud rate to {baudrate}"
        )
    if errors.get("ignored_host_bytes"):
        return (
            "the client sent bytes to an LD06/LD19, which takes no commands: it is a driver "
            "for another LIDAR (an RPLIDAR's requests start with A5); use its own device type"
        )
    if streams_unasked:
        if stats.revolutions_sent:
            return (
                f"the device streamed {stats.revolutions_sent} revolutions and nothing came of "
                f"them: check adapter TX -> board RX and GND, and that the board's driver reads "
                f"an LD06/LD19 at {baudrate} baud on the right port"
            )
        return ""
    if not stats.host_bytes:
        return (
            "the board never sent a request: check board TX -> adapter RX and GND, that its "
            "LIDAR driver runs on the right port, and that it started after the emulator "
            "(an A1 answers only requests; an LD06/LD19 driver never sends any)"
        )
    if errors.get("garbage_bytes") and not stats.requests_seen:
        return (
            f"only bytes that are no request: the board's line is at another baud rate than "
            f"{baudrate}, or its driver speaks another LIDAR's protocol"
        )
    lacks = {k: errors[k] for k in _LACKS if errors.get(k)}
    if lacks and not any(asked.get(r) for r in SCAN_REQUESTS):
        return (
            f"the driver asks for what this A1M8 lacks ({counts_text(lacks)}): e.g. "
            "sllidar_ros2's scan_mode Sensitivity; use scan_mode Standard, Express or empty"
        )
    if not any(asked.get(r) for r in SCAN_REQUESTS):
        return (
            f"the board asked ({counts_text(asked)}) but never started a scan: if it "
            "repeats a request, it does not hear the answers: check adapter TX -> board RX"
        )
    if stats.motor_off_revolutions and not stats.revolutions_sent:
        return (
            "a scan was asked for but the motor line kept the motor off (DTR asserted): "
            "unwire DTR -> DSR, or see 'motor line' in docs/hil.md"
        )
    return ""
