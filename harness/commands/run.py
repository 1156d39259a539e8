"""`fossbot-hil run`: run scenarios through a link and judge the answers."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import TYPE_CHECKING

from rich.console import Console

from harness.commands.arguments import (
    add_device_options,
    add_judging_options,
    add_link_option,
    add_node_options,
    add_scenario_overrides,
    not_empty,
)
from harness.commands.launch_option import add_launch_option, check_launch
from harness.commands.run_grading import RunGrading, add_grading_options, apply_grading
from harness.commands.run_steps import (
    open_report,
    prepared,
    scenario_of,
    settings_from,
    write_junit_file,
    write_report_file,
)
from harness.errors import ConfigError, Interrupted
from harness.report.console_text import print_safe as say

if TYPE_CHECKING:  # the rest is imported when a run starts (the parser is built for any command)
    from harness.judge.records import RunResult
    from harness.report.baseline import Baseline, Comparison
    from harness.scenario.schema import Scenario


NAME = "run"
HELP = "run scenarios and judge the node's answers"
FAIL_ON = ("failure", "regression")
ALIGNMENT = ("warn", "fail")  # what a misaligned board's /scan does: reported, or exit 1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scenarios",
        nargs="*",
        metavar="SCENARIO",
        help="shipped scenario name or path to a scenario file (default: all shipped)",
    )
    add_link_option(parser)
    add_scenario_overrides(parser)
    add_judging_options(parser)
    parser.add_argument("--gui", action="store_true", help="open the PyBullet viewer")
    parser.add_argument(
        "--junit-xml", type=not_empty, metavar="FILE", help="write a JUnit XML report"
    )
    parser.add_argument(
        "--out",
        type=not_empty,
        metavar="DIR",
        help="write a report folder: plots, summary.json, junit.xml, index.html "
        "(see docs/reports.md)",
    )
    parser.add_argument(
        "--animate",
        action="store_true",
        help="with --out: also an animated top-down view of each scenario, "
        "scenarios/<name>.gif (a few seconds per scenario)",
    )
    parser.add_argument(
        "--watch",
        action="store_true",
        help="run, then run again whenever the node's files (or scenario files given by path) "
        "change, failed scenarios first; rebuilds a --workspace package with colcon when "
        "needed; Ctrl-C to stop (see docs/watch.md)",
    )
    parser.add_argument(
        "--failed-first",
        action="store_true",
        help="run the scenarios that failed when this node last ran here first, then the "
        "rest (as pytest --ff; --watch does it always)",
    )
    parser.add_argument(
        "--baseline",
        type=not_empty,
        metavar="FILE",
        help="summary.json of an earlier run (or its --out folder): say what regressed, "
        "what was fixed and what still fails (see docs/ci.md)",
    )
    parser.add_argument(
        "--fail-on",
        choices=FAIL_ON,
        default="failure",
        help="exit 1 on any failed expectation (failure, the default), or only on a failure "
        "the --baseline does not know (regression: known failures are tolerated)",
    )
    parser.add_argument(
        "--alignment",
        choices=ALIGNMENT,
        default="warn",
        help="on a serial link (rplidar, ldlidar), check whether the board's /scan is the "
        "simulated scan turned or mirrored (its driver's invert / angle_offset_deg, or the "
        "LIDAR's mount) and report it with the likely fix: warn (the default) only reports; "
        "fail also exits 1 when it is. Accepted on links without a board scan (ros2, "
        "inprocess), which report nothing",
    )
    add_node_options(parser)
    add_launch_option(parser)
    add_device_options(parser)
    add_grading_options(parser)


def check_baseline(args: argparse.Namespace) -> Baseline | None:
    """The `--baseline` summary, read now so a bad file fails before anything runs."""
    if args.baseline is None:
        if args.fail_on == "regression":
            raise ConfigError("--fail-on regression needs --baseline FILE (a run to compare with)")
        return None
    from harness.report.baseline import load_baseline

    return load_baseline(args.baseline)


def compared(results: Sequence[RunResult], baseline: Baseline) -> Comparison:
    """This run's verdicts against the baseline's, as summary.json would hold them."""
    from harness.report.baseline import compare
    from harness.report.outputs import stored
    from harness.report.summary import scenario_entry

    return compare(baseline, [scenario_entry(stored(r), {}) for r in results])


def check_animate(args: argparse.Namespace) -> None:
    """`--animate` writes into the report folder, so it needs one."""
    if args.animate and args.out is None:
        raise ConfigError("--animate needs --out DIR (the animations go into the report folder)")


#: Options that make no sense in the edit-run loop, and why.
NOT_WITH_WATCH = {
    "gui": "--gui opens a viewer window for every scenario of every run",
    "animate": "--animate draws for seconds per scenario on every save",
    "baseline": "--baseline compares one run with another (for CI)",
}


def check_watch(args: argparse.Namespace) -> None:
    """`--watch` refuses what would make each save slow or has no meaning in a loop."""
    if not args.watch:
        return
    for name, why in NOT_WITH_WATCH.items():
        if getattr(args, name):
            raise ConfigError(f"--{name} cannot go with --watch: {why}; run it without --watch")
    if args.fail_on == "regression":
        raise ConfigError("--fail-on regression cannot go with --watch: a loop has no exit code")


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.nodes.forkserver import scope

    grading = apply_grading(args)  # --grading's scenarios and options, before any check
    check_animate(args)  # before a node or a fork server starts
    check_watch(args)
    check_launch(args, console)  # --launch: its file read now; exit 2 without `ros2 launch`
    baseline = check_baseline(args)

    with scope():  # whatever prepare() starts stops with the command (servers live across runs)
        if args.watch:
            from harness.commands.run_watch import watch

            return watch(args, console)
        return _run(args, console, baseline, grading)


def _run(
    args: argparse.Namespace, console: Console, baseline: Baseline | None, grading: RunGrading
) -> int:
    link, options, scenarios = prepared(args)
    grading.bind(scenarios)
    from harness.judge.alignment import run_alignment
    from harness.report.progress import RunProgress
    from harness.report.summary import alignment_fails
    from harness.report.terminal import print_results
    from harness.report.wall_clock import command_seconds
    from harness.runner.suite import run_suite
    from harness.watch.verdict_cache import verdict_cache

    cache = verdict_cache(link, options)
    if args.failed_first:
        scenarios = ordered_by_last_run(console, scenarios, cache.failed())
    report = open_report(args.out, animate=args.animate)
    if report is not None and report.cleared:
        say(console, f"--out: removed {report.cleared} scenario files of the run before")
    ran = scenario_of(scenarios)

    with RunProgress(console, grading.shown_names(scenarios)) as progress:

        def finished(result: RunResult) -> None:
            progress.on_result(result)
            scenario = ran(result)
            if report is not None:
                write_report_file(f"--out {args.out}", report.add, result, scenario)

        interrupted: Interrupted | None = None
        try:
            results = run_suite(
                scenarios,
                link,
                options,
                settings_from(args),
                on_tick=progress.on_tick,
                on_result=finished,
            )
        except Interrupted as stop:  # Ctrl-C or SIGTERM: report what was judged, then stop
            interrupted, results = stop, stop.results
    wall_s = command_seconds()
    cache.remember(results, interrupted=interrupted is not None)
    alignment = run_alignment(results)
    mode = args.alignment
    shown = grading.shown(results)  # a hidden scenario: its label, and whether it passed
    print_results(console, shown, wall_s=wall_s, alignment=alignment, alignment_mode=mode)
    comparison = compared(results, baseline) if baseline is not None else None
    if comparison is not None:
        from harness.report.terminal import print_comparison

        print_comparison(console, comparison)
    if report is not None:
        index = write_report_file(
            f"--out {args.out}",
            report.finish,
            wall_s,
            baseline=baseline,
            alignment=alignment,
            alignment_mode=mode,
        )
        say(console, f"report: {index}")
    if args.junit_xml:
        write_junit_file(args.junit_xml, shown, report)
    grading.finish(console, results, args, wall_s)  # the score; --gradescope's results.json
    if interrupted is not None:
        judged = sum(1 for r in results if not r.not_run)
        summary = f"{judged} of {len(scenarios)} scenarios judged, the last one in part"
        raise Interrupted(interrupted.signum, results, summary)
    if alignment_fails(alignment, mode):
        return 1  # the reason is the terminal's alignment line
    if args.fail_on == "regression" and comparison is not None:
        return 0 if comparison.ok else 1  # known failures tolerated
    return 0 if all(r.ok for r in results) else 1


def ordered_by_last_run(
    console: Console, scenarios: list[Scenario], failed: set[str]
) -> list[Scenario]:
    """`--failed-first`: the scenarios that failed last time first, and a line saying so."""
    from harness.watch.order import failed_first

    first = [s.name for s in scenarios if s.name in failed]
    if first:
        line = f"--failed-first: {len(first)} failed last time, run first: {', '.join(first)}"
    else:
        line = "--failed-first: none of these failed last time (or no earlier run): given order"
    say(console, line)
    return failed_first(scenarios, failed)
