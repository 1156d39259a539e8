"""Where a `fossbot-hil run` spends its wall time: a timeline of its phases.

    python benchmarks/run_timeline.py [RUN ARGUMENTS]     # e.g. approach_wall --link ros2

Runs the command in this process with timers around the calls that make up
a scenario (node start, the harness's ROS node, waiting for readiness, the
warm-up exchange, the run, closing), then prints on stderr when each began
and how long it took, in seconds since the harness was imported, and the totals
per phase. Nothing else is changed: the command's own output goes to stdout
as usual. docs/benchmarks.md shows how to read it.
"""

from __future__ import annotations

import atexit
import sys
import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

from harness.report.wall_clock import command_seconds

EVENTS: list[tuple[float, float, str]] = []  # (began, seconds, phase)


def timed(owner: Any, name: str, phase: str) -> None:
    """Wrap `owner.name` so each call is an event of `phase`."""
    original: Callable[..., Any] = getattr(owner, name)

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        began = command_seconds()
        started = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            EVENTS.append((began, time.perf_counter() - started, phase))

    setattr(owner, name, wrapper)


def report() -> None:
    totals: dict[str, float] = defaultdict(float)
    counts: dict[str, int] = defaultdict(int)
    for began, seconds, phase in sorted(EVENTS):
        print(f"{began:7.3f} {seconds:7.3f}  {phase}", file=sys.stderr)
        totals[phase] += seconds
        counts[phase] += 1
    print("\nphase totals (calls)", file=sys.stderr)
    for phase, seconds in sorted(totals.items(), key=lambda item: -item[1]):
        print(f"{seconds:7.3f} s  {phase} ({counts[phase]})", file=sys.stderr)
    print(f"{command_seconds():7.3f} s  command so far", file=sys.stderr)


def main() -> None:
    from harness import cli
    from harness.links import ros2
    from harness.nodes import forkserver, process
    from harness.ros import observer
    from harness.runner import scenario_run
    from harness.sim import simulation

    timed(forkserver.ForkServer, "__init__", "fork server: spawn")
    timed(forkserver.ForkServer, "_wait_ready", "fork server: wait until it has imported")
    timed(process.NodeProcess, "start", "node start (until its supervisor reports)")
    timed(observer.Observer, "__init__", "harness ROS node: create")
    timed(ros2.Ros2Link, "open", "link open: wait until the node is ready")
    timed(simulation.Simulation, "__init__", "world build")
    timed(ros2.Ros2Link, "warm_up", "warm-up exchange")
    timed(scenario_run, "judge_frames", "ticking (simulate, exchange, judge)")
    timed(ros2.Ros2Link, "close", "link close: wait for the node to stop")
    atexit.register(report)
    sys.argv = ["fossbot-hil", "run", *sys.argv[1:]]
    cli.entry()


if __name__ == "__main__":
    main()
