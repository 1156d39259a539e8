"""The ros2 stage: lockstep with the bundled reference node in its own process over Fast DDS.

The round trip is measured alone, one scan exchanged 100 times: in a run
the harness simulates the next scan while the node answers, which hides
part of it (that in-run figure is reported beside). Three rounds on one
open link, each measuring the ray-casting floor just before, so the
overhead compares costs measured at the same moment.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

from harness.bench.stage import LinkRun, StageResult, run_through, simulated_seconds
from harness.bench.stats import median, overhead_ratio, percentile
from harness.bench.workload import Workload, prepared_frames
from harness.links.base import Link, LinkOptions, create_link
from harness.links.kinds import ROS2

PING_PONGS = 100  # exchanges of one scan that give the round trip
ROUNDS = 3  # ping-pong and timed run, this many times on one open link (the median kept)


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


def process_cpu_s(pid: int | None) -> float | None:
    """CPU seconds (user + system) a live process has used so far, from /proc (Linux only)."""
    if pid is None:
        return None
    try:
        with open(f"/proc/{pid}/stat", "rb") as stat:
            fields = stat.read().rsplit(b")", 1)[1].split()
    except OSError:
        return None
    ticks = os.sysconf("SC_CLK_TCK")
    return (int(fields[11]) + int(fields[12])) / ticks  # utime, stime: fields 14 and 15


def process_peak_rss_mb(pid: int | None) -> float | None:
    """Peak resident memory of a live process since its exec (VmHWM, Linux only), MB."""
    if pid is None:
        return None
    try:
        with open(f"/proc/{pid}/status", "rb") as status:
            for line in status:
                if line.startswith(b"VmHWM:"):
                    return int(line.split()[1]) * 1024 / 1e6  # kB
    except OSError:
        pass
    return None


def ping_pong_s(link: Link, workload: Workload, count: int = PING_PONGS) -> list[float]:
    """One DDS round trip, alone: the same scan exchanged `count` times, nothing between
    (the overhead's floor: in a run an answer waits while the next scan is simulated)."""
    with prepared_frames(workload) as frames:
        scan = replace(next(iter(frames)).scan, stamp=0.0)  # runs start at t = 0: no clock jump
    link.warm_up(scan)
    trips = []
    for tick in range(count):
        answers = link.exchange(scan, tick)
        if answers.statuses and not answers.timed_out:
            trips.append(answers.statuses[0].after)
    return trips


def _node_pids(link: Link) -> list[int | None]:
    """The node under test and, for a board link, its LIDAR driver."""
    return [getattr(getattr(link, attr, None), "pid", None) for attr in ("process", "driver")]


@dataclass
class _Round:
    """One round on an open link: the round trips alone, then the timed run."""

    pings: list[float]
    run: LinkRun
    node_cpu_s: list[float | None]  # per process in _node_pids, over the run
    floor_s: float | None = None  # ray casting per scan, measured just before the round

    @property
    def scan_s(self) -> float:
        return self.run.seconds / max(1, len(self.run.result.records))

    def describe_rate(self) -> str:
        """Scans per second, or 'none' for a round that judged no scan."""
        return f"{1.0 / self.scan_s:.0f}" if self.scan_s > 0 else "none"

    @property
    def overhead(self) -> float | None:
        """The round's time per scan beyond its own floor and its own median round trip."""
        if self.floor_s is None or not self.pings:
            return None
        return overhead_ratio(self.scan_s, self.floor_s, median(self.pings))


def _measure_round(
    link: Link, workload: Workload, pids: list[int | None], floor: Callable[[], float] | None
) -> _Round:
    floor_s = floor() if floor is not None else None
    pings = ping_pong_s(link, workload)
    before = [process_cpu_s(pid) for pid in pids]
    after: list[float | None] = []

    def at_end() -> None:  # the last tick: the processes still run
        after.extend(process_cpu_s(pid) for pid in pids)

    run = run_through(link, workload, at_end=at_end)
    cpu = [
        b - a if a is not None and b is not None else None
        for a, b in zip(before, after or [None] * len(before), strict=True)
    ]
    return _Round(pings, run, cpu, floor_s)


def measure_link(
    link_name: str, workload: Workload, rounds: int = 1, floor: Callable[[], float] | None = None
) -> StageResult:
    """Open `link_name` with the reference node, run the workload through it, close it.

    Of several `rounds` the median is kept, so one slowed by the machine's
    other work moves nothing; with `floor` (ray casting s per scan) each
    round measures its own, so floor, round trip and lockstep share a moment.
    """
    options = LinkOptions(threshold=workload.threshold, scan_rate_hz=workload.scan_rate_hz)
    link = create_link(link_name, options)
    done: list[_Round] = []
    try:
        started = time.perf_counter()
        link.open()
        opened_s = time.perf_counter() - started
        pids = _node_pids(link)
        done.extend(_measure_round(link, workload, pids, floor) for _ in range(rounds))
        peaks = [process_peak_rss_mb(pid) for pid in pids]
        startup_s = getattr(link, "startup_s", opened_s)
    finally:
        started = time.perf_counter()
        link.close()
        closed_s = time.perf_counter() - started
    ordered = sorted(done, key=lambda r: r.scan_s)
    chosen = ordered[(len(ordered) - 1) // 2]
    run = chosen.run
    scans = len(run.result.records)
    node_cpu = [
        cpu * 1000.0 / scans if cpu is not None and scans else None for cpu in chosen.node_cpu_s
    ]
    trips = [t * 1000.0 for r in done for t in r.pings]
    in_run = [t * 1000.0 for t in round_trips_s(run)]
    waits = [w * 1000.0 for w in waits_s(run)]
    overheads = [r.overhead for r in done if r.overhead is not None]
    floors = [r.floor_s * 1000.0 for r in done if r.floor_s is not None]
    return StageResult(
        link_name,
        scans,
        run.seconds,
        simulated_seconds(run.result),
        extra={
            "startup_s": startup_s,
            "cpu_ms_per_scan": run.cpu_s * 1000.0 / scans if scans else None,
            "node_cpu_ms_per_scan": node_cpu[0],
            "driver_cpu_ms_per_scan": node_cpu[1],
            "node_peak_rss_mb": peaks[0],
            "driver_peak_rss_mb": peaks[1],
            "open_s": opened_s,
            "close_s": closed_s,
            "rounds": rounds,
            "round_scans_per_s": ", ".join(r.describe_rate() for r in done),
            "round_raycast_ms": ", ".join(f"{f:.3f}" for f in floors) or None,
            "round_overhead_ratios": ", ".join(f"{o:.3f}" for o in overheads) or None,
            "overhead_ratio": median(overheads) if overheads else None,
            "round_trip_ms_median": median(trips) if trips else None,
            "round_trip_ms_p99": percentile(trips, 99) if trips else None,
            "round_trip_in_run_ms_median": median(in_run) if in_run else None,
            "wait_ms_median": median(waits) if waits else None,
            "wait_ms_p99": percentile(waits, 99) if waits else None,
            "timed_out": sum(1 for r in run.result.records if r.answers.timed_out),
            "failed_ticks": sum(r.run.failed for r in done),
            "error": next((r.run.result.error for r in done if r.run.result.error), None),
        },
    )


def measure_ros2(workload: Workload, rounds: int = ROUNDS) -> StageResult:
    """The ros2 link: the harness publishes /scan to the node; each round measures its floor."""
    from harness.bench.raycast import measure_raycast

    return measure_link(ROS2, workload, rounds, floor=lambda: measure_raycast(workload).scan_s)
