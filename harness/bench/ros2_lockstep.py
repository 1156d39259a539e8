"""Stage 'ros2': lockstep with the bundled reference node in its own process over Fast DDS.

The link is opened (node started, graph matched: ``node_startup_s``), the
first scan is exchanged once untimed, then the workload's scans go through
the product's loop. The round trip of a scan is the link's own measure: from
the scan's publish returning to the node's status String being taken by the
harness (``Received.after`` of the first status), for every tick that did
not time out.
"""

from __future__ import annotations

import time

from harness.bench.stage import LinkRun, StageResult, run_through, simulated_seconds
from harness.bench.stats import median, percentile
from harness.bench.workload import Workload
from harness.links.base import LinkOptions, create_link


def round_trips_s(run: LinkRun) -> list[float]:
    """Publish-to-status seconds of every answered tick."""
    return [
        r.answers.statuses[0].after
        for r in run.result.records
        if r.answers.statuses and not r.answers.timed_out
    ]


def waits_s(run: LinkRun) -> list[float]:
    """How long the link waited per answered tick (the status, then any Bool grace)."""
    return [r.answers.waited for r in run.result.records if not r.answers.timed_out]


def measure_link(link_name: str, workload: Workload) -> StageResult:
    """Open `link_name` with the reference node, run the workload through it, close it."""
    options = LinkOptions(threshold=workload.threshold, scan_rate_hz=workload.scan_rate_hz)
    link = create_link(link_name, options)
    try:
        started = time.perf_counter()
        link.open()
        opened_s = time.perf_counter() - started
        run = run_through(link, workload)
        startup_s = getattr(link, "startup_s", opened_s)
    finally:
        started = time.perf_counter()
        link.close()
        closed_s = time.perf_counter() - started
    trips = [t * 1000.0 for t in round_trips_s(run)]
    waits = [w * 1000.0 for w in waits_s(run)]
    return StageResult(
        link_name,
        len(run.result.records),
        run.seconds,
        simulated_seconds(run.result),
        extra={
            "startup_s": startup_s,
            "open_s": opened_s,
            "close_s": closed_s,
            "round_trip_ms_median": median(trips) if trips else None,
            "round_trip_ms_p99": percentile(trips, 99) if trips else None,
            "wait_ms_median": median(waits) if waits else None,
            "wait_ms_p99": percentile(waits, 99) if waits else None,
            "timed_out": sum(1 for r in run.result.records if r.answers.timed_out),
            "failed_ticks": run.failed,
            "error": run.result.error,
        },
    )


def measure_ros2(workload: Workload) -> StageResult:
    """The ros2 link: the harness publishes /scan to the node."""
    return measure_link("ros2", workload)
