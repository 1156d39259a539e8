"""The inprocess stage: the whole lockstep loop through the inprocess link, no ROS.

Simulation, faults, the link, the oracle and the records. The reference
logic runs in a child forked from the harness (as every processing
function does), so one pipe round trip per scan is included; the gap to
the ros2 stage is the cost of DDS and of a node process.
"""

from __future__ import annotations

from harness.bench.stage import StageResult, run_through, simulated_seconds
from harness.bench.workload import Workload
from harness.links.base import LinkOptions, create_link
from harness.links.kinds import INPROCESS


def measure_inprocess(workload: Workload) -> StageResult:
    """Scans per second through the inprocess link and the oracle."""
    options = LinkOptions(threshold=workload.threshold, scan_rate_hz=workload.scan_rate_hz)
    link = create_link(INPROCESS, options)
    try:
        link.open()
        run = run_through(link, workload)
    finally:
        link.close()
    scans = len(run.result.records)
    cpu_ms = run.cpu_s * 1000.0 / max(1, scans)
    extra = {"cpu_ms_per_scan": cpu_ms, "failed_ticks": run.failed, "error": run.result.error}
    return StageResult(INPROCESS, scans, run.seconds, simulated_seconds(run.result), extra=extra)
