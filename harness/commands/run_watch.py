"""`fossbot-hil run --watch`: the run command's options, in the edit-run loop.

Everything `run` checks is checked once, before the first run (exit 2 as
`run`); after each run the verdict cache and `--out` / `--junit-xml` are
rewritten. Inside `run`'s fork-server scope, so a fork server started by
the first run serves every later one: the loop never restarts it.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from rich.console import Console

from harness.commands.arguments import unchecked_link_options
from harness.commands.run_steps import (
    open_report,
    prepared,
    run_link,
    scenario_of,
    selected,
    settings_from,
    write_junit_file,
    write_report_file,
)
from harness.errors import ConfigError
from harness.links.kinds import link_kind

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from harness.judge.records import RunResult, TickRecord
    from harness.links.base import LinkOptions
    from harness.scenario.schema import Scenario
    from harness.watch.sources import NodeSources

__all__ = ["watch", "watch_sources"]


def watch_sources(args: argparse.Namespace, link: str, options: LinkOptions) -> NodeSources:
    """The node's files and the scenario files given by path; ConfigError when none."""
    from harness.watch.sources import node_sources, scenario_sources

    sources = node_sources(link, options).plus(scenario_sources(args.scenarios))
    if not sources.watched:
        runs_node = link_kind(link).runs_node
        what = "node" if runs_node else "processing function"
        given = (
            "--processor FILE.py:FUNCTION"
            if not runs_node
            else "--node CMD or --workspace/--package/--executable"
        )
        raise ConfigError(
            f"--watch: nothing to watch: the bundled {what} is not yours to edit and no scenario "
            f"file was given by path; give yours with {given}"
        )
    return sources


def watch(args: argparse.Namespace, console: Console) -> int:
    """Run, then run again on every change, until Ctrl-C (130) or SIGTERM (143)."""
    link = run_link(args)
    sources = watch_sources(args, link, unchecked_link_options(args))  # before anything starts
    if sources.build is not None:
        from harness.grading.build import colcon_executable

        colcon_executable()  # colcon missing: exit 2 now, not at the first save
    link, options, _ = prepared(args)
    if args.out is not None:
        open_report(args.out).close()  # a bad folder fails now, not after the first run
    from harness.runner.settings import check_settings
    from harness.runner.suite import run_suite
    from harness.watch.loop import WatchLoop
    from harness.watch.screen import WatchScreen
    from harness.watch.verdict_cache import verdict_cache

    settings = settings_from(args)
    cache = verdict_cache(link, options)
    ran: list[Scenario] = []  # the order of the run in progress, for the reports

    def load() -> list[Scenario]:
        scenarios = selected(args.scenarios)
        check_settings(scenarios, settings)
        return scenarios

    def suite(
        order: Sequence[Scenario],
        on_tick: Callable[[TickRecord], None],
        on_result: Callable[[RunResult], None],
        on_judged: Callable[[RunResult], None],
    ) -> list[RunResult]:
        ran[:] = order
        hooks = {"on_tick": on_tick, "on_result": on_result, "on_judged": on_judged}
        return run_suite(order, link, options, settings, **hooks)

    def after(results: list[RunResult]) -> list[str]:
        cache.remember(results)
        return write_reports(args, results, ran)

    screen = WatchScreen(console, sources.description)
    loop = WatchLoop(sources, screen, load=load, suite=suite, after=after, failed=cache.failed())
    return loop.run_forever()


def write_reports(
    args: argparse.Namespace, results: list[RunResult], order: Sequence[Scenario]
) -> list[str]:
    """`--out` and `--junit-xml`, rewritten with this run; the lines that say where."""
    written = []
    report = open_report(args.out)
    if report is not None:
        try:
            scenario = scenario_of(order)
            for result in results:
                write_report_file(f"--out {args.out}", report.add, result, scenario(result))
            index = write_report_file(f"--out {args.out}", report.finish)
        finally:
            report.close()
        written.append(f"report: {index}")
    if args.junit_xml:
        write_junit_file(args.junit_xml, results, report)
        written.append(f"junit: {args.junit_xml}")
    return written
