"""Stage 'suite': scenarios end to end over ROS 2, node start-up included.

The lab trio through ``runner.run_suite`` in this process and as a command;
then what a user waits for after an edit, ``fossbot-hil run`` from spawn to
exit with the bundled node, a colcon workspace's node and the inprocess
link, taking turns so their ratios hold under a changing load; and where
the time goes, from the same scenarios run in this process. Each figure is
defined in docs/benchmarks.md.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from harness.bench.lab_workspace import build_lab_workspace, colcon_program, lab_package_source
from harness.bench.stage import StageResult
from harness.bench.suite_commands import alternate, cli_args, cli_wall_s
from harness.bench.workload import Workload
from harness.errors import HarnessError
from harness.links.base import LinkOptions
from harness.links.kinds import INPROCESS, ROS2
from harness.runner.suite import run_suite
from harness.scenario.files import shipped_scenarios
from harness.scenario.schema import Scenario

Figures = dict[str, float | int | str | None]
_SPLIT = ("inprocess_s", "startup_s", "ticking_s", "stop_s", "process_s")


def measure_suite(
    workload: Workload,
    *,
    cli: bool,
    suite_runs: int,
    student_split: bool = True,
    suite: Sequence[str] = (),
) -> StageResult:
    """The lab trio in this process (and as a command); the shipped suite as users run it
    (`suite`: only these of its scenarios, by name; empty: all of them)."""
    source, colcon = lab_package_source(), colcon_program()  # before anything is measured
    scenarios = list(workload.scenarios)
    started = time.perf_counter()
    results = run_suite(scenarios, ROS2, LinkOptions())
    seconds = time.perf_counter() - started
    scans = sum(len(r.records) for r in results)
    simulated = sum(r.records[-1].t + r.records[-1].scan.scan_time for r in results if r.records)
    extra: Figures = {
        "passed": sum(1 for r in results if r.ok),
        "scenarios": len(results),
        "cli_wall_s": cli_wall_s([s.name for s in scenarios]) if cli else None,
    }
    with tempfile.TemporaryDirectory(prefix="fossbot-hil-bench-") as folder:
        extra.update(_shipped_suite(suite_runs, student_split, Path(folder), source, colcon, suite))
    return StageResult("suite", scans, seconds, simulated, extra=extra)


def _shipped_suite(
    runs: int,
    student_split: bool,
    folder: Path,
    source: Path,
    colcon: str,
    names: Sequence[str] = (),
) -> Figures:
    """The shipped suite (or its scenarios `names`) three ways from spawn to exit, split."""
    workspace = build_lab_workspace(folder, source, colcon)
    shipped = [s for s in shipped_scenarios() if not names or s.name in names]
    bundled = _split("suite", "the bundled node", shipped, LinkOptions())
    student = (
        _split("student_suite", "the workspace node", shipped, workspace.link_options())
        if student_split
        else dict.fromkeys((f"student_suite_{k}" for k in _SPLIT), None)
    )
    walls = alternate(
        {
            "suite": [*names],
            "student_suite": [*names, *workspace.run_args()],
            "inprocess_suite": [*names, *cli_args(link=INPROCESS)],
        },
        runs,
    )
    out: Figures = {"student_build_s": workspace.build_s, **bundled, **student}
    for name, seconds in walls.items():
        out[f"{name}_s"] = statistics.median(seconds) if seconds else None
        out[f"{name}_runs_s"] = ", ".join(f"{w:.2f}" for w in seconds) or None
    for name in ("suite", "student_suite"):
        wall, inside = out[f"{name}_s"], out[f"{name}_inprocess_s"]
        both = isinstance(wall, float) and isinstance(inside, float)
        out[f"{name}_process_s"] = wall - inside if both else None
    out["student_suite_ratio"] = _ratio(out["student_suite_s"], out["suite_s"])
    out["inprocess_suite_ratio"] = _ratio(out["suite_s"], out["inprocess_suite_s"])
    return out


def _split(prefix: str, node: str, scenarios: Sequence[Scenario], options: LinkOptions) -> Figures:
    """The suite in this process over ROS 2: what it waited for in series (all must pass)."""
    started = time.perf_counter()
    results = run_suite(scenarios, ROS2, options)
    seconds = time.perf_counter() - started
    failed = [r for r in results if not r.ok]
    if failed:
        names = ", ".join(r.scenario for r in failed)
        why = f" ({failed[0].error})" if failed[0].error else ""
        raise HarnessError(f"the shipped suite with {node} failed in this process: {names}{why}")
    return {
        f"{prefix}_scenarios": len(results),
        f"{prefix}_scans": sum(len(r.records) for r in results),
        f"{prefix}_inprocess_s": seconds,
        f"{prefix}_startup_s": sum(r.startup_s for r in results),
        f"{prefix}_ticking_s": sum(r.wall_s for r in results),
        f"{prefix}_stop_s": sum(r.stop_s for r in results),
    }


def _ratio(top: object, bottom: object) -> float | None:
    """top / bottom when both were measured."""
    if isinstance(top, float) and isinstance(bottom, float) and bottom > 0:
        return top / bottom
    return None
