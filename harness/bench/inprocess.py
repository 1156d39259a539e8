"""Stage 'inprocess': the whole lockstep loop with the reference logic called in-process.

Simulation, faults, the link, the oracle and the records: everything a run
does except crossing a process boundary, so the gap to the ros2 stage is
the cost of DDS and of the node process.
"""

from __future__ import annotations

from harness.bench.stage import StageResult, run_through, simulated_seconds
from harness.bench.workload import Workload
from harness.links.base import LinkOptions, create_link


def measure_inprocess(workload: Workload) -> StageResult:
    """Scans per second through the inprocess link and the oracle."""
    options = LinkOptions(threshold=workload.threshold, scan_rate_hz=workload.scan_rate_hz)
    link = create_link("inprocess", options)
    try:
        link.open()
        run = run_through(link, workload)
    finally:
        link.close()
    return StageResult(
        "inprocess",
        len(run.result.records),
        run.seconds,
        simulated_seconds(run.result),
        extra={
            "cpu_ms_per_scan": run.cpu_s * 1000.0 / max(1, len(run.result.records)),
            "failed_ticks": run.failed,
            "error": run.result.error,
        },
    )
