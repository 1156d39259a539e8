"""A suite of scenarios, each with a fresh link, the next ones started ahead (link_pipeline)."""

from __future__ import annotations

import shlex
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext

from harness.errors import ConfigError, Interrupted
from harness.judge.records import RunResult, TickRecord
from harness.links.base import Link, LinkOptions, create_link, link_class
from harness.links.kinds import link_kind
from harness.nodes.forkserver import scope as fork_servers
from harness.nodes.setup_problems import setup_problem
from harness.runner.link_pipeline import AHEAD, BEHIND, LinkPipeline, ReportsBehind
from harness.runner.plan import plan_suite
from harness.runner.scenario_run import closed, run_scenario, run_through
from harness.runner.settings import RunSettings
from harness.scenario.schema import Scenario


def run_suite(
    scenarios: Sequence[Scenario],
    link_name: str,
    options: LinkOptions,
    settings: RunSettings = RunSettings(),
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
    on_result: Callable[[RunResult], None] | None = None,
    on_judged: Callable[[RunResult], None] | None = None,
) -> list[RunResult]:
    """Run each scenario through a link of its own, and report the results in order.

    `on_result` gets each once its link is closed, `on_judged` as soon as its
    ticks are judged (a scenario cut short by Ctrl-C only goes to `on_result`).
    Links that can overlap start ahead and stop behind (``link_pipeline``); once
    the software under test fails to come up, the rest are marked not run.
    """
    results: list[RunResult] = []
    if not scenarios:
        return results
    cls = link_class(link_name)
    # A serial link's next scenario follows in real time: the finished ones' reports are
    # made once its device session is over (ReportsBehind), in order.
    told = ReportsBehind(on_result, behind=cls.serial_line) if on_result is not None else None

    def report(result: RunResult) -> None:
        results.append(result)
        if told is not None:
            told(result)

    cls.prepare(options)
    plans = plan_suite(scenarios, link_name, options, settings)  # before anything starts
    first = plans[0].options
    with fork_servers(), _explicit_domain(link_name, first), cls.run_session(first) as session:

        def make(index: int) -> Link:
            return create_link(link_name, plans[index].options, session)

        ahead, behind = _overlap(cls, options)
        pipeline = LinkPipeline(make, len(scenarios), overlap=ahead > 0, ahead=ahead, behind=behind)
        failed_start: str | None = None
        index = 0
        try:
            for index, plan in enumerate(plans):
                scenario = plan.scenario
                if failed_start is not None:
                    pipeline.drain()
                    reason = f"not run: the node did not start in {failed_start}"
                    report(_not_run(scenario, link_name, reason))
                    continue
                started = time.perf_counter()
                try:
                    link = pipeline.take(index)  # starts it (unless ahead), and the next ones
                    taking = time.perf_counter() - started
                    result = run_through(
                        link,
                        lambda link, p=plan: run_scenario(p, link, on_tick=on_tick),
                        plan.not_started,
                    )
                except ConfigError as err:
                    if index == 0:
                        raise  # found before anything ran: a usage error (exit 2)
                    # Scenarios were judged: they keep their rows, this one says why.
                    result = plan.not_started(f"could not start: {err}", "")
                    result.not_started = True
                    result.startup_s = time.perf_counter() - started
                    failed_start = scenario.name
                    pipeline.drain()  # the scenarios before report first, in order
                    report(result)
                    continue
                result.startup_s += taking  # starting links is start-up too
                # A node up but deaf to the topics this scenario gave it (its node_topics)
                # may well hear the next scenario's: only a node that did not come up at
                # all leaves the rest not run.
                own_topics = result.never_ready and scenario.node_topics is not None
                if result.not_started and not own_topics:
                    failed_start = scenario.name
                    _check_setup(result, options)
                if on_judged is not None:
                    on_judged(result)
                pipeline.retire(link, _reporter(result, link, report))
        except KeyboardInterrupt as err:
            pipeline.drain()  # every process reaped; finished scenarios reported first
            if told is not None:
                told.finish()
            rest = scenarios[index:]
            raise _suite_interrupted(err, results, rest, link_name, on_result) from None
        finally:  # every link closed (in order: the last results are reported here)
            try:
                pipeline.drain()
            finally:
                if told is not None:
                    told.finish()
    return results


def _check_setup(result: RunResult, options: LinkOptions) -> None:
    """A node that could not start for want of rclpy is a usage error, not a verdict."""
    argv = shlex.split(options.node) if options.node else ()
    problem = setup_problem(f"{result.error}\n{result.diagnostics}", argv)
    if problem is not None:
        raise ConfigError(problem)


def _reporter(
    result: RunResult, link: Link, report: Callable[[RunResult], None]
) -> Callable[[float], None]:
    """Once `link` is closed: complete `result` (`closed`) and report it."""

    def on_closed(waited: float) -> None:
        closed(result, link, waited)
        report(result)

    return on_closed


def _overlap(cls: type[Link], options: LinkOptions) -> tuple[int, int]:
    """How many links to start ahead and leave stopping behind: where each has a domain
    of its own, AHEAD and BEHIND; where they share the run's session (a serial link's
    device and domain), what the class says; else none."""
    if not cls.starts_ahead:
        return 0, 0
    if cls.serial_line:
        return cls.links_ahead(options), 0  # type: ignore[attr-defined]
    return (AHEAD, BEHIND) if options.domain_id is None else (0, 0)


def _explicit_domain(link_name: str, options: LinkOptions) -> AbstractContextManager[object]:
    """An explicit domain id held for the whole suite (each scenario's link takes it again):
    no other run slips in between two scenarios, and an id in use fails before the first."""
    if options.domain_id is None or not link_kind(link_name).runs_node:
        return nullcontext()
    from harness.ros.domain import reserve_domain

    return reserve_domain(options.domain_id)


def _suite_interrupted(
    err: KeyboardInterrupt,
    done: list[RunResult],
    rest: Sequence[Scenario],
    link_name: str,
    on_result: Callable[[RunResult], None] | None,
) -> Interrupted:
    """What the suite judged before the signal: the finished scenarios, the
    interrupted one (its judged ticks, an error saying where it stopped), and
    the others not run."""
    stop = Interrupted.of(err)
    partial = list(stop.results)
    if not partial:  # interrupted before its first tick (starting the node, building the world)
        why = f"interrupted by {stop.name} before its first tick"
        partial = [RunResult(rest[0].name, link_name, 0, 0.0, "", error=why)]
    reason = f"not run: interrupted by {stop.name}"
    skipped = [_not_run(s, link_name, reason) for s in rest[1:]]
    if on_result is not None:
        for result in [*partial, *skipped]:
            on_result(result)
    return Interrupted(stop.signum, [*done, *partial, *skipped])


def _not_run(scenario: Scenario, link_name: str, reason: str) -> RunResult:
    return RunResult(scenario.name, link_name, 0, 0.0, "", error=reason, not_run=True)
