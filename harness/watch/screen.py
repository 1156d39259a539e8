"""What `run --watch` shows: one compact screen that redraws, or plain lines.

On a terminal, a rich Live screen: a row per scenario, drawn as soon as it
is judged, the footer, what the watch does, the first failure in full.
Anywhere else the same events as lines, each flushed when it happens, so a
script sees ``7 of 7 scenarios passed`` the moment it is known. Text from
the node is plain text, never markup, escaped and bounded (safe_text).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

from rich.console import Console, Group, RenderableType
from rich.live import Live
from rich.table import Table
from rich.text import Text

from harness.judge.records import RunResult, TickRecord
from harness.judge.verdicts import verdict_of
from harness.report.console_text import print_safe
from harness.report.summary import passed_line
from harness.report.terminal import VERDICT_STYLES
from harness.safe_text import DIAGNOSTICS_LIMIT, clip, for_terminal

__all__ = ["WatchScreen"]

REFRESH_S = 0.1  # while ticks come in, redraw at most this often
DIAGNOSTIC_LINES = 6
STATE_STYLES = {**VERDICT_STYLES, "pending": "dim", "running": "cyan"}


def _one_line(text: str) -> str:
    """Text from outside as one safe, bounded line."""
    return " ".join(for_terminal(clip(text)).split())


def _explanation(result: RunResult) -> str:
    """The first failure as `run` explains it, without the scenario's name before it
    (the row names it); a scenario not run says why."""
    text = result.first_failure or result.error or ""
    return _one_line(text.removeprefix(f"{result.scenario}: "))


@dataclass
class _Row:
    name: str
    state: str = "pending"
    seconds: float | None = None
    ticks: int = 0
    detail: str = ""
    judged: bool = False  # its verdict is known
    reported: bool = False  # its result is complete (its link closed)


class WatchScreen:
    """Feed it the loop's events; it draws them (terminal) or prints them (elsewhere)."""

    def __init__(self, console: Console, watched: Sequence[str]) -> None:
        self.console = console
        self.live_screen = console.is_terminal and not console.is_dumb_terminal
        self._watched = list(watched)
        self._live: Live | None = None
        self._rows: list[_Row] = []
        self._title = ""
        self._footer: Text | None = None
        self._status = ""
        self._notes: list[str] = []
        self._details: list[str] = []
        self._drawn_at = 0.0

    # -- life cycle -----------------------------------------------------------
    def __enter__(self) -> WatchScreen:
        if self.live_screen:
            self._live = Live(
                self._render(),
                console=self.console,
                auto_refresh=False,
                redirect_stdout=False,
                redirect_stderr=False,
            )
            self._live.start()
        else:
            for line in self._watched:
                self._line(f"watching {line}")
            self._line("Ctrl-C to stop")
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop_live()

    def _stop_live(self) -> None:
        if self._live is not None:
            self._draw(force=True)
            self._live.stop()
            self._live = None

    # -- events ---------------------------------------------------------------
    def run_started(self, number: int, names: Sequence[str], reason: str) -> None:
        """A run begins: every scenario pending, in the order it will run."""
        self._rows = [_Row(name) for name in names]
        self._title = f"run {number}: {reason}"
        self._footer = None
        self._status = "running"
        self._notes = []
        self._details = []
        self._line(f"{self._title}; order: {', '.join(for_terminal(n) for n in names)}")
        self._draw(force=True)

    def on_tick(self, record: TickRecord) -> None:
        """A tick judged (run_suite's on_tick): the first row not judged is running."""
        row = self._next(judged=True)
        if row is None:
            return
        row.ticks += 1
        fresh = row.state == "pending"
        row.state = "running"
        self._draw(force=fresh)

    def on_judged(self, result: RunResult) -> None:
        """A scenario judged (run_suite's on_judged): its verdict, at once, while its node
        may still be stopping."""
        self._show(self._row_for(result, judged=True), result)

    def on_result(self, result: RunResult) -> None:
        """A scenario's result complete (run_suite's on_result): the time its stop took and
        the node's last output join it; shown now if it was not judged (not run)."""
        row = self._row_for(result, judged=False)
        if row.judged:
            row.seconds = result.total_s
            self._draw()
        else:
            self._show(row, result)
        row.reported = True

    def _row_for(self, result: RunResult, *, judged: bool) -> _Row:
        """The row of the next result in run order (results come in the rows' order)."""
        row = self._next(judged=judged)
        if row is None or row.name != result.scenario:
            row = _Row(result.scenario)
            self._rows.append(row)
        return row

    def _show(self, row: _Row, result: RunResult) -> None:
        row.judged = True
        row.state = verdict_of(result)
        row.seconds = result.total_s
        row.ticks = len(result.records)
        row.detail = "" if result.ok else _explanation(result)
        words = f"{row.state:<7} {for_terminal(clip(row.name, 200))}  {row.seconds:.2f} s"
        self._line(f"{words}  {row.detail}" if row.detail else words)
        if not result.ok and not self._details and not result.not_run:
            self._details = [_one_line(result.first_failure or result.error or "")]
            tail = for_terminal(clip(result.diagnostics, DIAGNOSTICS_LIMIT)).rstrip()
            if tail:
                self._details += [f"  {line}" for line in tail.split("\n")[-DIAGNOSTIC_LINES:]]
        self._draw(force=True)

    def run_finished(self, results: Sequence[RunResult], seconds: float, *, since: str) -> None:
        """The footer, once every verdict is known: `run`'s 'N of M scenarios passed', and
        how long since `since`."""
        passed = sum(1 for r in results if r.ok)
        line = f"{passed_line(passed, len(results))} ({seconds:.2f} s since {since})"
        self._footer = Text(line, style="bold green" if passed == len(results) else "bold red")
        self._status = ""
        self._line(line)
        if not self.live_screen:
            for detail in self._details[1:]:  # the node's last output (the line is above)
                self._line(detail)
        self._draw(force=True)

    def run_closed(self) -> None:
        """Every link of the run closed: the rows' times are final."""
        self._draw(force=True)

    def status(self, text: str, lines: Sequence[str] = ()) -> None:
        """What the watch does (building, a problem), with lines to show under it."""
        self._status = _one_line(text)
        self._notes = [for_terminal(clip(line, 300)) for line in lines]
        self._line(self._status)
        for line in self._notes:
            self._line(f"  {line}")
        self._draw(force=True)

    def note(self, text: str) -> None:
        """A line under the run (e.g. where the report went)."""
        self._notes.append(_one_line(text))
        self._line(self._notes[-1])
        self._draw(force=True)

    def waiting(self) -> None:
        """Between runs: watching for the next save."""
        self._status = "watching for changes (Ctrl-C to stop)"
        self._line(self._status)
        self._draw(force=True)

    def stopped(self, signal_name: str) -> None:
        """Ctrl-C or SIGTERM: the last line."""
        self._status = f"stopped by {signal_name}"
        self._stop_live()
        print_safe(self.console, self._status)

    # -- drawing --------------------------------------------------------------
    def _next(self, *, judged: bool) -> _Row | None:
        """The first row not yet judged (`judged`), or not yet reported."""
        return next((r for r in self._rows if not (r.judged if judged else r.reported)), None)

    def _line(self, text: str) -> None:
        """Elsewhere than on a terminal: one line, written and flushed now."""
        if not self.live_screen:
            print_safe(self.console, text, limit=None)
            self.console.file.flush()

    def _draw(self, *, force: bool = False) -> None:
        if self._live is None:
            return
        now = time.monotonic()
        if not force and now - self._drawn_at < REFRESH_S:
            return
        self._drawn_at = now
        self._live.update(self._render(), refresh=True)

    def _render(self) -> RenderableType:
        parts: list[RenderableType] = [
            Text(f"watching {line}", style="dim") for line in self._watched
        ]
        parts.append(Text("Ctrl-C to stop", style="dim"))
        if self._title:
            parts.append(Text(self._title, style="bold"))
        table = Table(box=None, pad_edge=False, show_header=False, expand=False)
        table.add_column("state", no_wrap=True)
        table.add_column("scenario", no_wrap=True)
        table.add_column("time", justify="right", no_wrap=True)
        table.add_column("detail", no_wrap=True, overflow="ellipsis", max_width=120)
        for row in self._rows:
            ticks = f"{row.ticks} ticks" if row.state == "running" else ""
            when = f"{row.seconds:.2f} s" if row.seconds is not None else ticks
            table.add_row(
                Text(row.state, style=STATE_STYLES.get(row.state, "")),
                Text(for_terminal(clip(row.name, 200))),
                when,
                Text(row.detail),
            )
        if self._rows:
            parts.append(table)
        if self._footer is not None:
            parts.append(self._footer)
        if self._status:
            parts.append(Text(self._status, style="yellow"))
        parts += [Text(f"  {line}", style="dim") for line in self._notes]
        if self._details:
            parts.append(Text(""))
            parts += [
                Text(line, style="red" if i == 0 else "") for i, line in enumerate(self._details)
            ]
        return Group(*parts)
