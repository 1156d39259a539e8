"""The progress bar of many tasks: done of all, running, the ones that did not pass, rate
and time left."""

from __future__ import annotations

from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    Task,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.text import Text


class RateColumn(ProgressColumn):
    """Finished tasks per second since the first was submitted."""

    def __init__(self, unit: str) -> None:
        super().__init__()
        self.unit = unit

    def render(self, task: Task) -> Text:
        elapsed = task.elapsed or 0.0
        if not task.completed or elapsed <= 0:
            return Text(f"-- {self.unit}/s")
        return Text(f"{task.completed / elapsed:.2f} {self.unit}/s")


def task_progress(console: Console, unit: str, *, failed: str) -> Progress:
    """A bar whose task carries the fields `running` and `failed` (see `add_task`).

    `failed` says what the `failed` count counts, in the command's words
    ("not all passed", "did not finish"): a bare "3 failed" reads as three
    tasks that crashed when it may be three students with a failed scenario.
    """
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn(
            "{task.fields[running]} running, {task.fields[failed]} " + escape(failed),
        ),
        RateColumn(unit),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=console,
        transient=False,
    )


def add_task(progress: Progress, unit: str, total: int) -> Any:
    """The one task of a bar from `task_progress`: nothing done, running or failed yet."""
    return progress.add_task(unit, total=total, running=0, failed=0)
