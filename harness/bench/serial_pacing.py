"""Stage 'pacing': real-time RPLIDAR streaming at 115200 baud over a pty, timed at both ends.

A pty ignores the baud rate, so real-time emulation paces itself
(``serial_line.pacing``). The device server streams a scenario's
revolutions to ``line_reader`` in another process (the board's end); the
byte rate error and the revolutions' period jitter are taken at the reader
(what the board sees), the pacer's own view beside them. Revolutions are
handed over one period ahead, as a real-time producer should, so the
figures are the line's, not the producer's.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from harness.bench.stage import StageResult
from harness.bench.stats import (
    arrival_rate,
    jitter_ms,
    jitter_p99_ms,
    median,
    read_times,
    rplidar_revolution_starts,
)
from harness.errors import LinkError
from harness.runner.settings import RunSettings, fault_profile
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.devices.revolution import Sample
    from harness.serial_line.server import DeviceServer

SCAN_READY_S = 5.0  # the reader process starts and asks for a scan within this
READER_SLACK_S = 5.0  # beyond the streaming time, for the reader to start and report


def _revolutions(scenario: Scenario, count: int, samples_per_rev: int) -> list[list[Sample]]:
    """Device samples of the scenario's first `count` ticks (cycled if it is shorter)."""
    from harness.devices.revolution import samples_from_scan
    from harness.sim.simulation import Simulation

    spec = scenario.lidar_spec
    profile = fault_profile(scenario, RunSettings())
    rng = np.random.default_rng(scenario.seed)
    revs = []
    with Simulation(scenario) as sim:
        for tick in sim.ticks():
            scan = profile.emit(tick.truth, spec, rng, stamp=tick.t)
            revs.append(
                samples_from_scan(scan, samples_per_rev=samples_per_rev, max_range_m=spec.range_max)
            )
            if len(revs) == count:
                break
    return [revs[k % len(revs)] for k in range(count)]


def _started(server: DeviceServer, count: int) -> Callable[[object], bool]:
    """'`count` revolutions have started', for ``DeviceServer.wait_until``."""
    return lambda _device: server.stats().revolutions_sent >= count


def measure_pacing(scenario: Scenario, seconds: float) -> StageResult:
    """Stream about `seconds` of revolutions in real time; the line's rate and jitter."""
    from harness.devices.profiles import profile as device_profile
    from harness.links.kinds import default_serial_link, link_kind
    from harness.serial_line.ports import PtyPort
    from harness.serial_line.server import DeviceServer

    profile = device_profile(str(link_kind(default_serial_link()).device))
    period = scenario.lidar_spec.scan_time
    count = max(3, math.ceil(seconds / period))
    device = profile.make_device(scenario.lidar_spec.rate_hz)
    revs = _revolutions(scenario, count, profile.samples_per_rev(device, 1.0 / period))
    port = PtyPort()
    reader = subprocess.Popen(
        [sys.executable, "-m", "harness.bench.line_reader", port.slave_path, str(seconds + 3.0)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        server = DeviceServer(
            device, port, mode="realtime", baudrate=profile.baudrate, revolution_period_s=period
        )
        with server:
            if not server.wait_until(lambda d: d.mode == "scan", SCAN_READY_S):
                raise LinkError(f"the line reader did not ask for a scan in {SCAN_READY_S:g} s")
            for k, rev in enumerate(revs):
                if k and not server.wait_until(_started(server, k), 2 * period + 1.0):
                    raise LinkError(f"revolution {k - 1} did not start within two periods")
                server.send_revolution(rev, k)
            if not server.wait_idle(2 * period + 1.0):
                raise LinkError("the last revolution did not finish within two periods")
            stats = server.stats()
            written = [d.started_at for d in server.deliveries()]
            pacer_realtime = bool(server.realtime_priority)
        port.close()  # the reader sees the line close and reports
        out, err = reader.communicate(timeout=seconds + READER_SLACK_S)
    finally:
        port.close()
        if reader.poll() is None:
            reader.kill()
            reader.wait(5.0)
    if reader.returncode != 0:
        raise LinkError(f"line reader failed: {err.decode(errors='replace').strip()[-300:]}")
    seen = json.loads(out)
    reads = [(float(t), int(n)) for t, n in seen["reads"]]
    data = bytes.fromhex(seen["data"])
    starts = rplidar_revolution_starts(data)[: len(revs)]
    if len(starts) < len(revs):
        raise LinkError(f"the reader saw {len(starts)} of {len(revs)} revolutions")
    rev_bytes = len(revs[-1]) * 5
    segments = [(a, b) for a, b in zip(starts, starts[1:], strict=False)]
    segments.append((starts[-1], starts[-1] + rev_bytes))
    rate = arrival_rate(reads, segments)
    seen_starts = read_times(reads, starts)
    reader_jitter = jitter_ms(seen_starts, period)
    pacer_jitter = jitter_ms(written, period)
    nominal = profile.baudrate / 10.0
    pacing = stats.pacing
    assert pacing is not None
    streamed = len(revs) * period
    return StageResult(
        "pacing",
        len(revs),
        streamed,
        streamed,
        extra={
            "baudrate": profile.baudrate,
            "period_ms": period * 1000.0,
            "revolution_bytes": rev_bytes,
            "reader_realtime": bool(seen.get("realtime")),
            "pacer_realtime": pacer_realtime,
            "reader_rate_error_pct": (rate / nominal - 1.0) * 100.0 if rate else None,
            "reader_jitter_p99_ms": jitter_p99_ms(seen_starts, period),
            "reader_jitter_median_ms": median(reader_jitter) if reader_jitter else None,
            "reader_jitter_max_ms": max(reader_jitter) if reader_jitter else None,
            "pacer_rate_error_pct": pacing.mean_rate_error_pct,
            "pacer_jitter_p99_ms": pacing.period_jitter_p99_ms,
            "pacer_jitter_median_ms": median(pacer_jitter) if pacer_jitter else None,
            "underruns": stats.underruns,
            "overrun_bytes": stats.overrun_bytes,
        },
    )
