"""The progress bar: on a terminal during long runs, never in pipes or logs."""

from __future__ import annotations

import io

from rich.console import Console

from harness.links.base import LinkOptions
from harness.report.progress import RunProgress
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario

NAMES = ("approach_wall", "obstacle_at_side")


def _run(console: Console, names: tuple[str, ...], delay: float = 1.0) -> bool:
    """Run the scenarios with a progress bar; was it ever on screen?"""
    scenarios = [resolve_scenario(n) for n in names]
    with RunProgress(console, names, delay=delay) as progress:
        shown_during = progress.shown
        run_suite(
            scenarios,
            "inprocess",
            LinkOptions(),
            on_tick=progress.on_tick,
            on_result=progress.on_result,
        )
        shown_during |= progress.shown
    assert not progress.shown  # erased and stopped when the run ends
    return shown_during


def test_terminal_shows_scenarios_and_ticks() -> None:
    """Several scenarios on a terminal: a bar with scenarios done and ticks judged."""
    screen = io.StringIO()
    assert _run(Console(file=screen, force_terminal=True, width=120), NAMES)
    text = screen.getvalue()
    assert "2/2" in text and "scenarios" in text and " ticks, 0 failed" in text


def test_one_quick_scenario_shows_no_bar() -> None:
    """One scenario that ends within the delay never flashes a bar."""
    screen = io.StringIO()
    assert not _run(Console(file=screen, force_terminal=True), NAMES[:1], delay=60.0)
    assert screen.getvalue() == ""


def test_pipes_and_logs_get_nothing() -> None:
    """Not a terminal (CI, a pipe, a file): not a byte."""
    log = io.StringIO()
    assert not _run(Console(file=log), NAMES, delay=0.0)
    assert log.getvalue() == ""
