"""The terminal summary: one row per scenario, then the first failures in words."""

from __future__ import annotations

from collections.abc import Sequence

from rich.console import Console
from rich.table import Table

from harness.report.summary import verdict_of
from harness.scenario import Scenario
from harness.trace import RunResult

DIAGNOSTIC_LINES = 15
VERDICT_STYLES = {"PASS": "green", "FAIL": "red", "ERROR": "red", "NOT RUN": "yellow"}


def scenario_table(scenarios: Sequence[Scenario]) -> Table:
    """`fossbot-hil list`: name, LIDAR preset, faults and the one-line description."""
    table = Table(box=None, pad_edge=False)
    for column in ("scenario", "lidar", "faults", "description"):
        table.add_column(column, overflow="fold")
    for s in scenarios:
        faults = ", ".join(f if isinstance(f, str) else str(f.get("type", "?")) for f in s.faults)
        table.add_row(s.name, s.lidar.preset, faults or "clean", s.description)
    return table


def results_table(results: Sequence[RunResult]) -> Table:
    """`fossbot-hil run`: scenario / ticks / failed / verdict."""
    table = Table(box=None, pad_edge=False)
    for column in ("scenario", "link", "ticks", "failed", "verdict", "wall s"):
        table.add_column(
            column, justify="right" if column in ("ticks", "failed", "wall s") else "left"
        )
    for r in results:
        word = verdict_of(r)
        verdict = f"[{VERDICT_STYLES[word]}]{word}[/]"
        table.add_row(
            r.scenario,
            r.link,
            str(len(r.records)),
            str(len(r.failed_ticks)),
            verdict,
            f"{r.wall_s:.2f}",
        )
    return table


def print_results(console: Console, results: Sequence[RunResult]) -> None:
    """The table, then for each failed scenario its first failure and diagnostics."""
    console.print(results_table(results))
    failed = [r for r in results if not r.ok]
    shown: set[str] = set()
    for r in failed:
        if r.not_run:
            continue
        console.print()
        console.print(
            r.first_failure, style="bold red", markup=False, highlight=False, soft_wrap=True
        )
        more = len(r.failed_ticks) - 1
        if more > 0:
            console.print(f"  ({more} more failed tick{'s' if more > 1 else ''})", highlight=False)
        if r.error and r.failed_ticks and r.error not in (r.first_failure or ""):
            console.print(f"  run ended: {r.error}", markup=False, highlight=False, soft_wrap=True)
        if r.diagnostics in shown:
            console.print("  (node output as above)", highlight=False)
        elif r.diagnostics:
            shown.add(r.diagnostics)
            tail = r.diagnostics.rstrip().splitlines()[-DIAGNOSTIC_LINES:]
            console.print("  " + "\n  ".join(tail), highlight=False, markup=False, soft_wrap=True)
    not_run = [r for r in failed if r.not_run]
    if not_run:
        console.print()
        reason = (not_run[0].error or "").removeprefix("not run: ")
        console.print(
            f"{len(not_run)} not run: {reason}",
            highlight=False,
            markup=False,
        )
    total = len(results)
    passed = total - len(failed)
    console.print()
    console.print(f"{passed} of {total} scenarios passed", highlight=False)
