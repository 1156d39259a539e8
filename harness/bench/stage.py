"""What one bench stage measured, and the loop that times a link stage.

The link stages time the product's own loop (``runner.judge_frames``) from
the first scan to the last tick judged, so what they report is what a run
costs; the link's start-up and the node's stop are timed apart.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from harness.bench.workload import Workload, prepared_frames
from harness.judge.records import RunResult, TickRecord
from harness.links.base import Link
from harness.runner.frames import Frame, judge_frames


@dataclass
class StageResult:
    """Scans a stage pushed through in `seconds` of wall time, and its own extra figures."""

    name: str
    scans: int
    seconds: float
    simulated_s: float  # simulated time those scans cover (scans x scan time)
    extra: dict[str, float | int | str | None] = field(default_factory=dict)

    @property
    def scans_per_s(self) -> float:
        return self.scans / self.seconds if self.seconds > 0 else float("inf")

    @property
    def scan_s(self) -> float:
        """Wall time per scan."""
        return self.seconds / self.scans

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second."""
        return self.simulated_s / self.seconds if self.seconds > 0 else float("inf")


@dataclass
class LinkRun:
    """One link stage's run: the product's result plus when each tick was judged."""

    result: RunResult
    seconds: float  # first scan sent (after warm-up) to last tick judged
    judged_at: list[float]
    cpu_s: float = 0.0  # CPU time of this process (all its threads) over the same stretch

    @property
    def failed(self) -> int:
        return len(self.result.failed_ticks)


def run_through(
    link: Link, workload: Workload, *, at_end: Callable[[], None] | None = None
) -> LinkRun:
    """Judge the workload's chained frames through an opened `link`, timed from after a
    warm-up exchange to the last judged tick (`at_end` is called then), worlds' set-up
    taken out. No diagnostics (they stop a node), so the link can run it again; CPU time
    beside, as on a shared machine it moves less than wall time."""
    oracle = workload.oracle()
    names = "+".join(s.name for s in workload.scenarios)
    result = RunResult(names, link.name, 0, workload.threshold, faults="scenarios' own")
    judged_at: list[float] = []
    with prepared_frames(workload) as frames:
        first = next(frames)
        link.warm_up(first.scan)
        exhausted = False
        end = {"cpu": 0.0, "setup": 0.0, "setup_cpu": 0.0}

        def all_frames() -> Iterator[Frame]:
            nonlocal exhausted
            yield first
            yield from frames
            exhausted = True

        def on_tick(record: TickRecord) -> None:
            nonlocal exhausted
            judged_at.append(time.perf_counter())
            end.update(cpu=time.process_time(), setup=frames.setup_s, setup_cpu=frames.setup_cpu_s)
            if exhausted and at_end is not None:  # the last tick: the frames ran out before it
                exhausted = False
                at_end()

        setup, setup_cpu = frames.setup_s, frames.setup_cpu_s
        cpu_started = time.process_time()
        started = time.perf_counter()
        judge_frames(all_frames(), link, oracle, result, on_tick=on_tick, diagnose=False)
    if not judged_at:
        return LinkRun(result, 0.0, judged_at)
    seconds = judged_at[-1] - started - (end["setup"] - setup)
    cpu_s = end["cpu"] - cpu_started - (end["setup_cpu"] - setup_cpu)
    return LinkRun(result, seconds, judged_at, max(0.0, cpu_s))


def simulated_seconds(run: RunResult) -> float:
    """Simulated time the judged ticks cover (the last tick's time plus one scan)."""
    if not run.records:
        return 0.0
    last = run.records[-1]
    return last.t + last.scan.scan_time
