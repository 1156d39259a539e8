"""`fossbot-hil emulate`: serve a scenario's scans as a LIDAR device on a port.

For users testing their own drivers: the harness is the device, in real
time, and nothing else runs. With no port named, a pty pair stands in for
the cable and its path is printed first, so a script can read it and point
its driver there. No ROS is needed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from harness.devices.profiles import DeviceProfile
from harness.devices.revolution import samples_from_scan
from harness.errors import ConfigError
from harness.faults.link import LINE_KINDS, LineDamage, LinkFaults, scan_periods
from harness.runner.settings import RunSettings, effective_seed, fault_profile
from harness.scenario.schema import Scenario

IDLE_WAIT_S = 5.0  # after the last revolution: let the line drain


@dataclass(frozen=True)
class EmulationSummary:
    """What was served, for the closing line and for tests."""

    revolutions: int
    revolutions_streamed: int  # the rest found the device idle (not asked to scan)
    bytes_written: int
    requests_seen: int | None
    mean_rate_error_pct: float | None
    period_jitter_p99_ms: float | None


def check_device_faults(faults: LinkFaults) -> None:
    """A device on a line can drift and have its bytes damaged; the rest is not its doing."""
    other = [f.kind for f in faults.items if f.kind != "rate_drift" and f.kind not in LINE_KINDS]
    if other:
        raise ConfigError(
            f"faults {', '.join(other)}: emulate plays a LIDAR device, which cannot "
            "drop, repeat, reorder, delay or restamp the board's scans (rate_drift and "
            "line faults apply)"
        )


def emulate(
    profile: DeviceProfile,
    scenario: Scenario,
    *,
    port: str | None = None,
    settings: RunSettings | None = None,
    announce: Callable[[str], None] = print,
) -> EmulationSummary:
    """Serve every revolution of `scenario` in real time until it ends."""
    settings = settings or RunSettings()
    from harness.serial_line.ports import PtyPort, SerialPort
    from harness.serial_line.server import DeviceServer
    from harness.sim.simulation import Simulation

    spec = scenario.lidar_spec
    faults = fault_profile(scenario, settings)  # a mistake here opens nothing
    seed = effective_seed(scenario, settings)
    check_device_faults(faults.link)
    drift = faults.link.get("rate_drift")
    device = profile.make_device(spec.rate_hz)
    line = SerialPort(port, profile.baudrate) if port else PtyPort()
    announce(f"port: {port or line.slave_path}")
    rng = np.random.default_rng(seed)
    revolutions = 0
    server = DeviceServer(
        device,
        line,
        mode="realtime",
        baudrate=profile.baudrate,
        revolution_period_s=spec.scan_time,
    )
    if faults.link.on_line:
        server.damage = LineDamage(faults.link, seed)
    periods = scan_periods(drift, spec.rate_hz, seed) if drift is not None else None
    try:
        with server, Simulation(scenario) as sim:
            started = time.monotonic()
            for tick in sim.ticks(periods):
                due = started + tick.t
                while (left := due - time.monotonic()) > 0:
                    time.sleep(min(left, 0.05))  # pacing the scenario clock, not syncing
                    server.wait_idle(0)  # surfaces a vanished port promptly
                scan = faults.emit(tick.truth, spec, rng, stamp=tick.t)
                samples = samples_from_scan(
                    scan,
                    samples_per_rev=profile.samples_per_rev(device, 1.0 / tick.period),
                    max_range_m=spec.range_max,
                )
                server.send_revolution(samples, tick.tick, tick.period)
                revolutions += 1
            server.wait_idle(IDLE_WAIT_S)
            stats = server.stats()
    finally:
        line.close()
    pacing = stats.pacing
    return EmulationSummary(
        revolutions=revolutions,
        revolutions_streamed=stats.revolutions_sent,
        bytes_written=stats.bytes_written,
        requests_seen=stats.requests_seen,
        mean_rate_error_pct=pacing.mean_rate_error_pct if pacing else None,
        period_jitter_p99_ms=pacing.period_jitter_p99_ms if pacing else None,
    )
