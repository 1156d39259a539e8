"""A progress bar for long runs, on a terminal only.

Pipes, files and CI logs get nothing from here: their output stays the
table and the explanations. The bar is transient (erased when the run
ends) so the terminal keeps only the summary.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    SpinnerColumn,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
)

from harness.judge.records import RunResult, TickRecord
from harness.safe_text import clip, for_terminal

__all__ = ["RunProgress"]

SINGLE_SCENARIO_DELAY_S = 1.0  # one scenario: show the bar only once it takes this long


class RunProgress:
    """Feed it run_suite's on_tick/on_result; it draws scenarios done, ticks, failures,
    one scenario's only after `delay` seconds, so quick runs never flash a bar."""

    def __init__(
        self, console: Console, scenarios: Sequence[str], *, delay: float = SINGLE_SCENARIO_DELAY_S
    ) -> None:
        self.enabled = console.is_terminal and not console.is_dumb_terminal
        self._console = console
        self._names = list(scenarios)
        self._delay = delay if len(self._names) == 1 else 0.0
        self._progress: Progress | None = None
        self._task: TaskID | None = None
        self._started = 0.0
        self._done = 0
        self._ticks = 0
        self._failed = 0

    def __enter__(self) -> RunProgress:
        self._started = time.monotonic()
        if self._delay <= 0:
            self._show()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._progress.stop()
            self._progress = None

    @property
    def shown(self) -> bool:
        """Is the bar on screen (for tests)?"""
        return self._progress is not None

    def _current(self) -> str:
        """The scenario running, as plain text (its name could read as markup)."""
        name = self._names[self._done] if self._done < len(self._names) else "done"
        return for_terminal(clip(name, 200))

    def _show(self) -> None:
        if not self.enabled or self._progress is not None:
            return
        self._progress = Progress(
            SpinnerColumn(),
            TextColumn("{task.description}", markup=False),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("scenarios · {task.fields[ticks]} ticks, {task.fields[failed]} failed"),
            TimeElapsedColumn(),
            console=self._console,
            transient=True,
        )
        self._task = self._progress.add_task("", total=len(self._names), ticks=0, failed=0)
        self._update()  # the counts so far
        self._progress.start()

    def _update(self) -> None:
        if self._progress is not None and self._task is not None:
            self._progress.update(
                self._task,
                description=self._current(),
                completed=self._done,
                ticks=self._ticks,
                failed=self._failed,
            )

    def on_tick(self, record: TickRecord) -> None:
        """One tick judged: count it (and show the bar if this run got long)."""
        self._ticks += 1
        self._failed += not record.verdict.ok
        if self._progress is None and time.monotonic() - self._started >= self._delay:
            self._show()
        self._update()

    def on_result(self, result: RunResult) -> None:
        """One scenario finished: advance the bar."""
        self._done += 1
        self._update()
