"""Stage 'suite': scenarios end to end over ROS 2, node start-up included.

``lab_suite_wall_s`` is ``runner.run_suite`` over the lab's three scenarios
in this process, as the CLI and the pytest plugin run them; its CLI figure
(``lab_suite_cli_wall_s``) is ``fossbot-hil run`` with the three names, from
spawn to exit.

``suite_s`` is what a user waits for after an edit: ``fossbot-hil run`` (all
shipped scenarios, the bundled reference node, a fresh process, interpreter
start included), the median of a few runs. Its split comes from the same
scenarios run in this process: waiting for nodes to come up
(``suite_startup_s``), ticking (``suite_ticking_s``: simulating, exchanging,
judging), waiting for nodes to stop (``suite_stop_s``); ``suite_process_s``
is the rest of the command (interpreter start, imports, output, exit).
"""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
import time

from harness.bench.stage import StageResult
from harness.bench.workload import Workload
from harness.errors import HarnessError
from harness.links.base import LinkOptions
from harness.runner.suite import run_suite
from harness.scenario.files import shipped_scenarios

CLI_TIMEOUT_S = 120.0


def measure_suite(workload: Workload, *, cli: bool, suite_runs: int) -> StageResult:
    """The lab trio in this process (and as a command); the shipped suite as a user runs it."""
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
        **_shipped_suite(suite_runs),
    }
    return StageResult("suite", scans, seconds, simulated, extra=extra)


def _shipped_suite(runs: int) -> dict[str, float | int | None]:
    """`fossbot-hil run` from spawn to exit (median of `runs`) and where its time goes."""
    shipped = shipped_scenarios()
    started = time.perf_counter()
    results = run_suite(shipped, "ros2", LinkOptions())
    inprocess_s = time.perf_counter() - started
    if not all(r.ok for r in results):
        failed = [r.scenario for r in results if not r.ok]
        raise HarnessError(f"the shipped suite failed in this process: {', '.join(failed)}")
    walls = [_cli_wall_s([]) for _ in range(runs)]
    suite_s = statistics.median(walls) if walls else None
    return {
        "suite_scenarios": len(results),
        "suite_scans": sum(len(r.records) for r in results),
        "suite_s": suite_s,
        "suite_runs_s": ", ".join(f"{w:.2f}" for w in walls) or None,
        "suite_inprocess_s": inprocess_s,
        "suite_startup_s": sum(r.startup_s for r in results),
        "suite_ticking_s": sum(r.wall_s for r in results),
        "suite_stop_s": sum(r.stop_s for r in results),
        "suite_process_s": suite_s - inprocess_s if suite_s is not None else None,
    }


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
