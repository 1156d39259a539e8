"""The edit-run loop: run, wait for a change, build when needed, run again, until Ctrl-C.

What failed last runs first. A change saved during a run or a build starts
the next round as soon as this one ends; a failed build skips the run. A
usage error ends the first run (exit 2, as `run`); later ones (a scenario
file saved half-edited) are shown and the loop waits for the next save.
Ctrl-C or SIGTERM reaps a run's nodes or stops a build first (exit 130, 143).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Collection, Sequence
from typing import TYPE_CHECKING

from harness.ctrl_c import remembered_ctrl_c
from harness.errors import HarnessError, Interrupted
from harness.judge.records import RunResult, TickRecord
from harness.watch.changes import ChangeFeed, Changes
from harness.watch.order import failed_first
from harness.watch.screen import WatchScreen
from harness.watch.sources import Build, NodeSources

if TYPE_CHECKING:
    from harness.scenario.schema import Scenario

__all__ = ["WatchLoop"]

WAIT_S = 0.5  # one bounded wait for a change; the loop waits again until one comes
SHOWN_CHANGES = 3

Report = Callable[[RunResult], None]
#: run_suite for the scenarios given, with its on_tick, on_result and on_judged
Suite = Callable[
    [Sequence["Scenario"], Callable[[TickRecord], None], Report, Report], list[RunResult]
]


def _changed_names(changes: Changes) -> str:
    names = sorted({p.name for p in changes.paths})
    more = f" and {len(names) - SHOWN_CHANGES} more" if len(names) > SHOWN_CHANGES else ""
    return ", ".join(names[:SHOWN_CHANGES]) + more


class WatchLoop:
    """Runs the suite on every change of `sources` until interrupted; `after(results)`
    keeps a run's judged results (on Ctrl-C, those judged so far), returning lines to show."""

    def __init__(
        self,
        sources: NodeSources,
        screen: WatchScreen,
        *,
        load: Callable[[], list[Scenario]],
        suite: Suite,
        after: Callable[[list[RunResult]], list[str]],
        failed: Collection[str] = (),
    ) -> None:
        self.sources = sources
        self.screen = screen
        self.load = load
        self.suite = suite
        self.after = after
        self.failed = set(failed)
        self.runs = 0
        self._scenarios: list[Scenario] | None = None
        self._build_due = False  # the last build failed: the next change builds again
        self._judged: list[RunResult] = []  # the verdicts of the run in progress

    def run_forever(self) -> int:
        """The loop; returns the exit code when Ctrl-C or SIGTERM ends it."""
        feed = ChangeFeed(self.sources.watched, self.sources.matches)
        try:
            with self.screen, feed, remembered_ctrl_c() as pressed:
                changes = Changes(frozenset(), time.monotonic())
                while True:
                    self._round(changes)
                    changes = feed.wait(0.0)  # saved during the round: go again at once
                    if not changes:
                        self.screen.waiting()
                    while not changes:
                        if pressed.is_set():  # its KeyboardInterrupt was lost on the way
                            raise KeyboardInterrupt
                        changes = feed.wait(WAIT_S)
        except KeyboardInterrupt as err:  # Interrupted too: run_suite reaped its nodes
            stop = Interrupted.of(err)
            self.screen.stopped(stop.name)
            judged, self._judged = self._judged, []
            if judged:  # stopped in a run: keep what it judged, as `run` does
                with contextlib.suppress(HarnessError):
                    for line in self.after(judged):
                        self.screen.note(line)
            return stop.exit_code

    def _round(self, changes: Changes) -> None:
        """Build if the change needs it, then run (the first round: just run)."""
        first = self.runs == 0
        since = "the start" if first else "the change"
        reason = "first run" if first else f"changed {_changed_names(changes)}"
        build = self.sources.build
        if build is not None and (self._build_due or build.needed(changes.paths)):
            if not self._build(build):
                return
        try:
            if self._scenarios is None or self.sources.scenario_files & changes.paths:
                self._scenarios = self.load()
            self._run(self._scenarios, reason, since, changes.seen_at)
        except HarnessError as err:  # ConfigError included
            if first:
                raise
            self.screen.status(f"not run: {err}", ["waiting for the next save"])

    def _build(self, build: Build) -> bool:
        from harness.watch.rebuild import build_log, rebuild

        self.screen.status(f"building {build.package} with colcon ... (log: {build_log(build)})")
        outcome = rebuild(build)
        self._build_due = not outcome.ok
        if outcome.ok:
            self.screen.status(f"built {build.package} in {outcome.seconds:.1f} s")
            return True
        self.screen.status(
            f"build failed: {outcome.error} (log: {outcome.log}); not run until the next save",
            outcome.tail,
        )
        return False

    def _run(self, scenarios: list[Scenario], reason: str, since: str, seen_at: float) -> None:
        order = failed_first(scenarios, self.failed)
        self.runs += 1
        first = [s.name for s in order if s.name in self.failed]
        if first:  # last time: the run before, or (the first run) the command before
            reason += f"; failed last time first: {', '.join(first)}"
        self.screen.run_started(self.runs, [s.name for s in order], reason)
        judged: list[RunResult] = []
        self._judged = judged

        def on_judged(result: RunResult) -> None:
            judged.append(result)
            self.screen.on_judged(result)
            if len(judged) == len(order):  # the footer as soon as the last verdict is known
                self.screen.run_finished(judged, time.monotonic() - seen_at, since=since)

        results = self.suite(order, self.screen.on_tick, self.screen.on_result, on_judged)
        if len(judged) < len(order):  # some not run: known once the suite is over
            self.screen.run_finished(results, time.monotonic() - seen_at, since=since)
        self.screen.run_closed()
        for result in results:
            if not result.not_run:
                (self.failed.discard if result.ok else self.failed.add)(result.scenario)
        for line in self.after(results):
            self.screen.note(line)
        self._judged = []  # kept until written: Ctrl-C before this writes them again
