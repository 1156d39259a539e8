"""Stage 'suite': the lab's three scenarios end to end over ROS 2, node start-up included.

``lab_suite_wall_s`` is ``runner.run_suite`` in this process, as the CLI and
the pytest plugin run it: per scenario a fresh node process is started and
matched, the scenario runs, the node is stopped. The CLI figure also counts
a fresh interpreter's start and imports: ``fossbot-hil run`` with the three
names, as a user types it, timed from spawn to exit.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

from harness.bench.stage import StageResult
from harness.bench.workload import Workload
from harness.errors import HarnessError
from harness.links.base import LinkOptions
from harness.runner import run_suite

CLI_TIMEOUT_S = 120.0


def measure_suite(workload: Workload, *, cli: bool) -> StageResult:
    """Wall time of the three runs in-process, and of the same command in a fresh process."""
    scenarios = list(workload.scenarios)
    started = time.perf_counter()
    results = run_suite(scenarios, "ros2", LinkOptions())
    seconds = time.perf_counter() - started
    scans = sum(len(r.records) for r in results)
    simulated = sum(r.records[-1].t + r.records[-1].scan.scan_time for r in results if r.records)
    extra: dict[str, float | int | str | None] = {
        "passed": sum(1 for r in results if r.ok),
        "scenarios": len(results),
        "cli_wall_s": _cli_wall_s([s.name for s in scenarios]) if cli else None,
    }
    return StageResult("suite", scans, seconds, simulated, extra=extra)


def _cli_wall_s(names: list[str]) -> float:
    """`fossbot-hil run NAMES` from spawn to exit (exit code 0 required)."""
    exe = shutil.which("fossbot-hil", path=os.path.dirname(sys.executable))
    argv = [exe] if exe else [sys.executable, "-m", "harness.cli"]
    started = time.perf_counter()
    done = subprocess.run(
        [*argv, "run", *names],
        capture_output=True,
        timeout=CLI_TIMEOUT_S,
        check=False,
    )
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).decode(errors="replace").strip()[-300:]
        raise HarnessError(f"fossbot-hil run exited {done.returncode}: {tail}")
    return seconds
