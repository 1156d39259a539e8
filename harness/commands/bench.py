"""`fossbot-hil bench`: how fast each stage of the harness runs on this machine.

Stage by stage (docs/benchmarks.md). Exit 0 when the bench ran, met or not:
the targets are measured, not asserted; 1 when a stage could not run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.table import Table

from harness.bench import STAGES
from harness.report.console_text import print_safe as say

if TYPE_CHECKING:  # the stages are imported when the bench runs
    from harness.bench.stage import StageResult

NAME = "bench"
HELP = "measure the harness's speed, stage by stage, against its targets"

_THROUGHPUT_ROWS = (
    ("raycast", "ray casting alone (PyBullet floor)"),
    ("synthesis", "scan synthesis with faults"),
    ("inprocess", "inprocess lockstep"),
    ("ros2_lockstep", "ROS 2 lockstep, node process"),
    ("serial_lockstep", "serial lockstep, virtual board"),
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object, nothing else")
    parser.add_argument(
        "--quick", action="store_true", help="fewer scans and shorter streaming (for tests)"
    )
    parser.add_argument(
        "--only", metavar="STAGE[,STAGE]", help=f"run only these stages ({', '.join(STAGES)})"
    )


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.bench.run import BenchPlan, parse_stages, run_bench

    plan = BenchPlan(quick=args.quick, stages=parse_stages(args.only))
    progress = None if args.json else _progress(Console(stderr=True, highlight=False))
    report = run_bench(plan, on_stage=progress)
    if args.json:
        sys.stdout.write(json.dumps(_finite(report), indent=2) + "\n")
        sys.stdout.flush()
    else:
        print_report(console, report)
    return 1 if report["errors"] else 0


def _progress(err: Console):
    def on_stage(name: str, stage: StageResult | None, seconds: float) -> None:
        err.print(f"{name}: {'done' if stage else 'failed'} in {seconds:.1f} s")

    return on_stage


def _finite(value: Any) -> Any:
    """JSON has no inf or NaN: such a figure (a stage too fast to time) becomes null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _num(value: float | None, places: int = 1) -> str:
    return "-" if value is None else f"{value:,.{places}f}"


def print_report(console: Console, report: dict[str, Any]) -> None:
    """The machine, a throughput table, a table of the other figures, the targets."""
    m = report["machine"]
    load = m.get("load_average_start")
    load_text = " ".join(f"{x:.2f}" for x in load) if load else "unknown"
    machine = f"{m['cpu']}, {m['cores']} cores, Python {m['python']}, {m['os']}"
    say(console, f"{machine}; load average at start {load_text}")
    console.print()
    console.print(throughput_table(report))
    console.print()
    console.print(figures_table(report))
    for stage, reason in report["errors"].items():
        console.print(f"{stage}: not measured: {reason}", style="red", markup=False)
    met = [t for t in report["targets"] if t["met"]]
    measured = [t for t in report["targets"] if t["met"] is not None]
    console.print()
    console.print(
        f"{len(met)} of {len(measured)} targets met; bench took {report['bench_wall_s']:.1f} s",
        highlight=False,
    )


def throughput_table(report: dict[str, Any]) -> Table:
    table = Table(box=None, pad_edge=False)
    for column in ("stage", "scans/s", "ms/scan", "x raycast", "real-time factor"):
        table.add_column(column, justify="left" if column == "stage" else "right")
    for key, label in _THROUGHPUT_ROWS:
        rate = report.get(f"{key}_scans_per_s")
        ratio = 1.0 if key == "raycast" and rate else report["ratio_to_raycast"].get(key)
        table.add_row(
            label,
            _num(rate, 0),
            _num(1000.0 / rate if rate else None, 3),
            _num(ratio, 2),
            _num(report["real_time_factor"].get(key), 0),
        )
    return table


def figures_table(report: dict[str, Any]) -> Table:
    targets = {t["key"]: t for t in report["targets"]}
    rows = (
        ("ros2_lockstep_scans_per_s", "ROS 2 lockstep", "scans/s", 0),
        ("ros2_round_trip_ms_median", "ROS 2 round trip, median", "ms", 3),
        ("ros2_round_trip_ms_p99", "ROS 2 round trip, p99", "ms", 3),
        ("overhead_ratio", "harness overhead per scan", "%", 1),
        ("ros2_cpu_ms_per_scan", "ROS 2 lockstep: harness CPU per scan", "ms", 3),
        ("ros2_node_cpu_ms_per_scan", "ROS 2 lockstep: node CPU per scan", "ms", 3),
        ("node_startup_s", "node start-up (start to ready)", "s", 2),
        ("lab_suite_wall_s", "lab trio over ROS 2", "s", 2),
        ("lab_suite_cli_wall_s", "lab trio, CLI from spawn", "s", 2),
        ("suite_s", "shipped suite, `fossbot-hil run` from spawn", "s", 2),
        ("suite_startup_s", "  of it: waiting for nodes to come up", "s", 2),
        ("suite_ticking_s", "  of it: ticking (simulate, exchange, judge)", "s", 2),
        ("suite_stop_s", "  of it: waiting for nodes to stop", "s", 2),
        ("suite_process_s", "  of it: interpreter, imports, output, exit", "s", 2),
        ("student_suite_s", "the same, workspace node (colcon build of node/)", "s", 2),
        ("student_suite_startup_s", "  of it: waiting for nodes to come up", "s", 2),
        ("student_suite_ticking_s", "  of it: ticking (simulate, exchange, judge)", "s", 2),
        ("student_suite_stop_s", "  of it: waiting for nodes to stop", "s", 2),
        ("student_suite_process_s", "  of it: interpreter, imports, output, exit", "s", 2),
        ("student_build_s", "  colcon build of the workspace (not in it)", "s", 2),
        ("inprocess_suite_s", "the same, `--link inprocess`", "s", 2),
        ("student_suite_ratio", "shipped suite, workspace node / bundled node", "x", 2),
        ("inprocess_suite_ratio", "shipped suite, bundled node / inprocess link", "x", 2),
        ("grade_per_student_s", "`fossbot-hil grade`, per student (default suite)", "s", 2),
        ("grade_runs_s", "  their `fossbot-hil run`s back to back", "s", 2),
        ("grade_ratio", "  grade / their runs on the same workers", "x", 2),
        ("grade_runs_out_s", "  their runs back to back, each writing its report", "s", 2),
        ("grade_ratio_out", "  grade / those runs on the same workers", "x", 2),
        ("hil_suite_s", "real-time HIL suite (virtual board, bundled driver)", "s", 2),
        ("hil_gap_median_s", "  gap between scenarios, median", "s", 2),
        ("hil_gap_max_s", "  gap between scenarios, longest", "s", 2),
        ("serial_rate_error_pct", "serial byte rate error (reader)", "%", 3),
        ("serial_jitter_p99_ms", "revolution jitter p99 (reader)", "ms", 3),
        ("serial_jitter_median_ms", "revolution jitter median (reader)", "ms", 3),
        ("serial_jitter_max_ms", "revolution jitter max (reader)", "ms", 3),
        ("serial_pacer_rate_error_pct", "serial byte rate error (pacer)", "%", 3),
        ("serial_pacer_jitter_p99_ms", "revolution jitter p99 (pacer)", "ms", 3),
        ("peak_rss_mb", "peak memory, harness + node (+ driver)", "MB", 0),
        ("peak_rss_mb_harness", "peak memory, harness alone", "MB", 0),
    )
    table = Table(box=None, pad_edge=False)
    for column in ("figure", "value", "unit", "target", "met"):
        table.add_column(column, justify="right" if column == "value" else "left")
    for key, label, unit, places in rows:
        value = report.get(key)
        shown = value * 100.0 if unit == "%" and key == "overhead_ratio" and value else value
        target = targets.get(key)
        met = (
            ""
            if target is None
            else {True: "[green]met[/]", False: "[red]not met[/]"}.get(target["met"], "-")
        )
        table.add_row(label, _num(shown, places), unit, target["target"] if target else "", met)
    return table
