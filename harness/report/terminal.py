"""The terminal summary: one row per scenario, then the first failures in words.

Names, statuses, errors and a node's output are printed as plain text, never
rich markup, with every non-printable character shown as its escape
(harness.safe_text): what a node writes cannot drive the terminal.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from typing import TYPE_CHECKING

from rich.console import Console
from rich.table import Table
from rich.text import Text

from harness.judge.records import RunResult
from harness.judge.verdicts import RunVerdict, verdict_of
from harness.option_names import named, worded
from harness.report.baseline import KINDS
from harness.report.console_text import print_safe
from harness.report.summary import alignment_fails, passed_line
from harness.safe_text import DIAGNOSTICS_LIMIT, clip, for_terminal
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.judge.alignment import Alignment
    from harness.report.baseline import Comparison

DIAGNOSTIC_LINES = 15
VERDICT_STYLES = {
    RunVerdict.PASS: "green", RunVerdict.FAIL: "red", RunVerdict.ERROR: "red",
    RunVerdict.NOT_RUN: "yellow",
}  # fmt: skip
CHANGE_STYLES = {"regressed": "bold red", "fixed": "green", "still failing": "yellow"}


def _plain(text: object, style: str = "") -> Text:
    """A table cell shown as written (no markup), safe and bounded."""
    return Text(for_terminal(clip(str(text))), style=style)


def scenario_table(scenarios: Sequence[Scenario]) -> Table:
    """`fossbot-hil list`: name, LIDAR preset, faults and the one-line description."""
    table = Table(box=None, pad_edge=False)
    for column in ("scenario", "lidar", "faults", "description"):
        table.add_column(column, overflow="fold")
    for s in scenarios:
        faults = ", ".join(f if isinstance(f, str) else str(f.get("type", "?")) for f in s.faults)
        table.add_row(
            _plain(s.name), _plain(s.lidar.preset), _plain(faults or "clean"), _plain(s.description)
        )
    return table


def results_table(results: Sequence[RunResult], wall_s: float | None = None) -> Table:
    """`fossbot-hil run`: scenario / ticks / failed / verdict / time, and a total row (the
    command's wall time when known). A scenario's time is what it cost the run: start,
    run and stop of the software under test, work overlapping another scenario once."""
    table = Table(box=None, pad_edge=False)
    for column in ("scenario", "link", "ticks", "failed", "verdict", "time s"):
        table.add_column(
            column, justify="right" if column in ("ticks", "failed", "time s") else "left"
        )
    for r in results:
        word = verdict_of(r)
        table.add_row(
            _plain(r.scenario),
            _plain(r.link),
            str(len(r.records)),
            str(len(r.failed_ticks)),
            Text(word, style=VERDICT_STYLES[word]),
            f"{r.total_s:.2f}",
        )
    if len(results) > 1 or wall_s is not None:
        total = wall_s if wall_s is not None else sum(r.total_s for r in results)
        table.add_row(
            "total",
            "",
            str(sum(len(r.records) for r in results)),
            str(sum(len(r.failed_ticks) for r in results)),
            "",
            f"{total:.2f}",
            style="bold",
            end_section=False,
        )
    return table


def print_results(
    console: Console,
    results: Sequence[RunResult],
    *,
    wall_s: float | None = None,
    alignment: Alignment | None = None,
    alignment_mode: str = "warn",
) -> None:
    """The table, then for each failed scenario its first failure and diagnostics;
    `wall_s`, the command's wall time so far, goes in the total row; `alignment`,
    the fit of the board's /scan (serial links), a line at the end."""
    console.print(results_table(results, wall_s))
    failed = [r for r in results if not r.ok]
    shown: set[str] = set()
    for r in failed:
        if r.not_run:
            continue
        console.print()
        print_safe(console, r.first_failure or "", style="bold red")
        more = len(r.failed_ticks) - 1
        if more > 0:
            console.print(f"  ({more} more failed tick{'s' if more > 1 else ''})", highlight=False)
        if r.error and r.failed_ticks and not _told(r.error, r.first_failure or ""):
            print_safe(console, f"  run ended: {r.error}")
        diagnostics = without_notes(r.diagnostics, r.notes)
        if diagnostics in shown:
            console.print("  (node output as above)", highlight=False)
        elif diagnostics:
            shown.add(diagnostics)
            lines = for_terminal(clip(diagnostics, DIAGNOSTICS_LIMIT)).rstrip().split("\n")
            print_safe(console, "  " + "\n  ".join(lines[-DIAGNOSTIC_LINES:]), limit=None)
    not_run = [r for r in failed if r.not_run]
    if not_run:
        console.print()
        reason = (not_run[0].error or "").removeprefix("not run: ")
        print_safe(console, f"{len(not_run)} not run: {reason}")
    notes = run_notes(results)
    if notes:
        console.print()
    for note in notes:
        print_safe(console, f"note: {note}", style="yellow")
    total = len(results)
    passed = total - len(failed)
    console.print()
    console.print(passed_line(passed, total), highlight=False)
    if any(r.warning_rule == "required" for r in results):
        console.print(
            worded(
                "judged with {warning_when_clear} required: warning False was due on every scan "
                "with nothing within the threshold"
            ),
            highlight=False,
        )
    for line in node_start_lines(results):
        console.print(line, style="dim", highlight=False, markup=False, soft_wrap=True)
    gaps = gap_line(results)
    if gaps:
        console.print(gaps, highlight=False, markup=False)
    if alignment is not None:
        print_alignment(console, alignment, mode=alignment_mode)


def _told(error: str, first_failure: str) -> bool:
    """Does the first failure already say what ended the run (its tick's failure is the
    error, e.g. the node's crash)?"""
    _, _, what = error.partition(": ")
    return error in first_failure or bool(what) and what in first_failure


def without_notes(diagnostics: str, notes: Sequence[str]) -> str:
    """The diagnostics without the run's notes, which are printed once for the run."""
    if not notes:
        return diagnostics
    return "\n".join(line for line in diagnostics.split("\n") if line not in notes)


def run_notes(results: Sequence[RunResult]) -> list[str]:
    """Each note of the run once (a node's warning on another topic, say), in order."""
    return list(dict.fromkeys(note for r in results for note in r.notes))


def node_start_lines(results: Sequence[RunResult]) -> list[str]:
    """'node: python3 node.py, started by fork ...', once per way the run started it."""
    ways = dict.fromkeys(r.node_start for r in results if r.node_start)
    return [f"node: {for_terminal(clip(way, 300))}" for way in ways]


def gap_line(results: Sequence[RunResult]) -> str:
    """'between scenarios the device kept streaming: 0.8-1.2 s (median 0.9 s)'; '' when
    no result had a run-long device session."""
    gaps = sorted(r.gap_s for r in results if r.gap_s is not None)
    if not gaps:
        return ""
    lead = "between scenarios the device kept streaming"
    low, high = f"{gaps[0]:.1f}", f"{gaps[-1]:.1f}"
    if low == high:
        return f"{lead}: {low} s"
    return f"{lead}: {low}-{high} s (median {statistics.median(gaps):.1f} s)"


def print_alignment(console: Console, alignment: Alignment, *, mode: str = "warn") -> None:
    """`run` on a serial link: whether the board's /scan is the truth turned or mirrored;
    quiet when aligned or unknown, a warning when misaligned, a failure with `--alignment fail`."""
    line, style = f"alignment: {alignment.text()}", ""
    if alignment_fails(alignment, mode):
        failed = f"FAILED ({named('alignment')} fail)"
        line, style = f"alignment: {failed}: {alignment.text()}", "bold red"
    elif alignment.misaligned:
        line, style = f"alignment: WARNING: {alignment.text()}", "bold yellow"
    print_safe(console, line, style=style)


def print_comparison(console: Console, comparison: Comparison) -> None:
    """`run --baseline`: what differs from the baseline as a whole, then one row per
    scenario whose verdict is not a plain "still passing", then the counts."""
    console.print()
    print_safe(
        console,
        f"compared with the baseline {comparison.baseline} (fossbot-hil {comparison.harness})",
        style="bold",
    )
    for note in comparison.notes:
        print_safe(console, f"  note: {note}", style="yellow")
    rows = [c for c in comparison.changes if c.kind != "still passing"]
    if rows:
        table = Table(box=None, pad_edge=False)
        for column in ("change", "scenario", "faults", "then", "now", "why"):
            table.add_column(column, overflow="fold")
        for c in sorted(rows, key=lambda c: KINDS.index(c.kind)):
            table.add_row(
                Text(c.kind, style=CHANGE_STYLES.get(c.kind, "")),
                _plain(c.scenario),
                _plain(c.faults),
                c.then or "-",
                c.now or "-",
                _plain(c.reason),
            )
        console.print(table)
    console.print(comparison.headline(), highlight=False)
    unknown = comparison.unknown_failures
    if unknown:
        named = ", ".join(f"{c.scenario} [{c.faults}] ({c.kind})" for c in unknown)
        print_safe(console, f"failing, and not known from the baseline: {named}", style="bold red")
    elif any(c.fails_now for c in comparison.changes):
        console.print("no regression: every failure is known from the baseline", highlight=False)
    else:
        console.print("no regression: nothing fails", highlight=False)
