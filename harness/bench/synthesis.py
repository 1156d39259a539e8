"""Stage 'synthesis': simulation plus fault models, the emitted scans and nothing else.

The runner's frame stream without a link: each tick moves the robot, casts
the rays and applies the scenario's fault profile. A second pass applies
the ``harsh`` profile (noise, dropouts, ghosts, NaN driver: every random
draw) to the same scenarios, to show the most the fault stage can cost.
"""

from __future__ import annotations

import time
from dataclasses import replace

from harness.bench.stage import StageResult
from harness.bench.workload import Workload, prepared_frames

HARSH = ("harsh",)


def _timed_frames(workload: Workload) -> tuple[int, float, float]:
    """(scans, wall seconds, simulated seconds) of consuming the frame stream: the first
    scan before the clock starts, as in the other stages; building worlds taken out."""
    scans, last_t, scan_time = 0, 0.0, 0.0
    with prepared_frames(workload) as frames:
        first = next(frames)  # the first world is built before the clock starts
        scans, last_t, scan_time = 1, first.t, first.scan.scan_time
        setup = frames.setup_s
        started = time.perf_counter()
        for frame in frames:
            scans += 1
            last_t, scan_time = frame.t, frame.scan.scan_time
        seconds = time.perf_counter() - started - (frames.setup_s - setup)
    return scans, seconds, last_t + scan_time


def measure_synthesis(workload: Workload) -> StageResult:
    """Scans per second of simulation + faults (scenarios' own profiles; harsh as an extra)."""
    scans, seconds, simulated = _timed_frames(workload)
    harsh = replace(workload, settings=replace(workload.settings, faults=HARSH))
    harsh_scans, harsh_seconds, _ = _timed_frames(harsh)
    extra = {"harsh_scans_per_s": harsh_scans / harsh_seconds}
    return StageResult("synthesis", scans, seconds, simulated, extra=extra)
