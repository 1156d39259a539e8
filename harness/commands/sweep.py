"""`fossbot-hil sweep`: one node through scenarios x faults x seeds x thresholds, on Dask."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console

from harness.atomic_write import write_atomically
from harness.commands.arguments import (
    FAULTS_METAVAR,
    add_judging_options,
    add_link_option,
    add_node_options,
    name_list,
    not_empty,
    whole_number,
)
from harness.commands.cluster_options import (
    KILLED,
    add_cluster_options,
    checked_runs_options,
    describe_cluster,
    run_result,
    runs_client,
)
from harness.errors import ConfigError
from harness.judge.verdicts import RunVerdict
from harness.report.console_text import print_safe as say

if TYPE_CHECKING:
    from harness.campaign.plan import RunSpec, Variation
    from harness.campaign.results import ResultsTable
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings

NAME = "sweep"
HELP = "run one node through every combination of scenarios, faults, seeds and thresholds"
MAX_RUNS = 100_000


def _numbers(text: str, positive: bool, problem: str) -> list[float]:
    """A comma list of finite numbers (> 0 if `positive`); `problem` names one that is not."""
    values = []
    for item in name_list(text):
        try:
            value = float(item)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or (positive and value <= 0):
            raise argparse.ArgumentTypeError(f"{problem}, got {item[:20]!r}")
        values.append(value)
    return values


def _thresholds(text: str) -> list[float]:
    return _numbers(text, True, "a threshold is metres > 0")


def _variation(text: str) -> tuple[str, list[float]]:
    """NAME=LEVEL[,LEVEL]: a generated variation and its levels."""
    from harness.scenario.variations import VARIATIONS

    name, sep, levels = text.partition("=")
    name = name.strip()
    if not sep or name not in VARIATIONS:
        known = ", ".join(VARIATIONS)
        raise argparse.ArgumentTypeError(f"give NAME=LEVEL[,LEVEL] with NAME one of {known}")
    positive = name in ("speed", "wall_distance")
    kind = "a number > 0" if positive else "a number"
    return name, _numbers(levels, positive, f"{name}: a level is {kind}")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--scenario",
        type=name_list,
        action="append",
        default=[],
        metavar="NAME[,NAME]",
        help="scenario name or file (repeatable; default: every shipped one)",
    )
    parser.add_argument(
        "--faults",
        metavar=FAULTS_METAVAR,
        help="fault levels: each item one level, a profile or an inline fault (default: each "
        "scenario's own)",
    )
    seed_count = whole_number("seed count", 1, 10_000)
    parser.add_argument(
        "--seed-count",
        dest="seeds",
        type=seed_count,
        default=1,
        metavar="N",
        help="run every combination with seeds 0..N-1, replacing the scenarios' own seeds "
        "(default 1: seed 0 only); not one seed, as --seed of other commands",
    )
    parser.add_argument(  # the old name, kept so scripts still work
        "--seeds", dest="seeds", type=seed_count, help=argparse.SUPPRESS
    )
    parser.add_argument(
        "--thresholds",
        type=_thresholds,
        metavar="M[,M]",
        help="warning thresholds in metres (default: each scenario's own)",
    )
    parser.add_argument(
        "--vary",
        type=_variation,
        action="append",
        default=[],
        metavar="NAME=L[,L]",
        help="generated scenario variations, each a factor (repeatable): wall_distance (m), "
        "start_dx, start_dy (m), start_dyaw (rad), speed (x); docs/campaigns.md",
    )
    add_link_option(parser)
    add_judging_options(parser, threshold=False)  # --thresholds is a factor here
    parser.add_argument(
        "--out",
        type=not_empty,
        default="sweep",
        metavar="DIR",
        help="where results.csv and summary.txt go (default ./sweep)",
    )
    parser.add_argument(
        "--resume", action="store_true", help="run only what DIR/results.csv does not hold yet"
    )
    parser.add_argument(
        "--parquet",
        action="store_true",
        help="also write DIR/results.parquet at the end (needs fossbot-hil[parquet])",
    )
    add_cluster_options(parser)
    add_node_options(parser, domain_help=argparse.SUPPRESS)  # refused: each run reserves one


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.campaign.factors import explain
    from harness.campaign.parquet import check_parquet_available, write_parquet
    from harness.campaign.plan import plan
    from harness.campaign.results import columns_for, rows_to_resume

    options, judged = checked_runs_options(args, "sweep")
    if args.parquet:
        check_parquet_available()
    varied = _varied(args.vary)
    specs = plan(*_levels(args, varied))
    if len(specs) > MAX_RUNS:
        raise ConfigError(f"{len(specs)} runs; at most {MAX_RUNS} in one sweep")
    out = Path(args.out)
    path, columns = out / "results.csv", columns_for(list(varied))
    kept = rows_to_resume(path, columns) if args.resume else []
    done = {row["key"] for row in kept}
    todo = [spec for spec in specs if spec.key not in done]
    say(
        console,
        f"sweep: {len(specs)} run{'s' if len(specs) != 1 else ''} "
        f"({len(specs) - len(todo)} done already) "
        f"{describe_cluster(args.scheduler, args.workers)}, results in {path}",
    )
    if todo:
        kept = _run_all(console, todo, args, options, judged, path, columns).rows
    wanted = {spec.key for spec in specs}
    rows = [row for row in kept if row["key"] in wanted]
    lines = explain(rows, varied=list(varied))
    write_atomically(out / "summary.txt", ("\n".join(lines) + "\n").encode())
    if args.parquet:
        say(console, f"wrote {write_parquet(out / 'results.parquet', rows, columns)}")
    for line in lines:
        say(console, line)
    failed = sum(row["verdict"] != RunVerdict.PASS for row in rows)
    return 0 if not failed else 1


def _varied(items: list[tuple[str, list[float]]]) -> dict[str, list[float]]:
    """--vary items by name, in the one order runs are keyed by (each name once)."""
    from harness.scenario.variations import ORDER

    levels: dict[str, list[float]] = {}
    for name, values in items:
        if name in levels:
            raise ConfigError(f"--vary {name}: given twice (list its levels in one --vary)")
        levels[name] = values
    return {name: levels[name] for name in ORDER if name in levels}


def _levels(
    args: argparse.Namespace, varied_levels: dict[str, list[float]]
) -> tuple[list[str], list[str], list[int], list[Any], list[Variation]]:
    """Each factor's levels, checked now, so a mistake exits 2 before any cluster starts."""
    from harness.campaign.plan import SCENARIO_FAULTS, variation_levels
    from harness.faults.sensor import split_fault_text
    from harness.runner.settings import RunSettings, check_settings
    from harness.scenario.files import resolve_scenario, shipped_scenarios
    from harness.scenario.variations import varied

    chosen = [name for item in args.scenario for name in item]
    scenarios = [resolve_scenario(name) for name in chosen] if chosen else shipped_scenarios()
    variations = variation_levels(varied_levels)
    scenarios = [varied(s, dict(v)) for s in scenarios for v in variations]  # each one checked
    faults = split_fault_text(args.faults) if args.faults else [SCENARIO_FAULTS]
    thresholds: list[Any] = args.thresholds or [None]
    for level in faults:
        items = None if level == SCENARIO_FAULTS else [level]
        for threshold in thresholds:
            check_settings(scenarios, RunSettings(threshold=threshold, faults=items))
    names = chosen or [s.name for s in shipped_scenarios()]
    return names, faults, list(range(args.seeds)), thresholds, variations


def _run_all(
    console: Console,
    todo: list[RunSpec],
    args: argparse.Namespace,
    options: LinkOptions,
    judged: RunSettings,
    path: Path,
    columns: tuple[str, ...],
) -> ResultsTable:
    """Run every spec on the cluster, write each row as it finishes, show progress; the
    table is emptied only once the cluster answers (a mistyped --scheduler costs nothing)."""
    from harness.campaign.results import ResultsTable
    from harness.campaign.task import run_one
    from harness.cluster.progress import add_task, task_progress
    from harness.cluster.window import Window

    with runs_client(args, console, "harness.campaign.task") as client:
        table = ResultsTable(path, resume=args.resume, columns=columns)

        def submit(spec: RunSpec) -> Any:
            return client.submit(
                run_one, spec, link_name=args.link, options=options, judged=judged, pure=False
            )

        window = Window(client, todo, submit)
        failed = 0
        with task_progress(console, "runs", failed="not passed") as progress:
            bar = add_task(progress, "runs", len(todo))
            for index, future in window:
                row = _row_of(future, todo[index])
                table.add(row)
                failed += row["verdict"] != RunVerdict.PASS
                progress.update(bar, advance=1, failed=failed, running=len(window.running))
    return table


def _row_of(future: Any, spec: RunSpec) -> dict[str, Any]:
    """The run's row; a run Dask gave up on (it killed its worker every time) is a row too."""
    done = run_result(future, f"sweep stopped: run {spec.key}", "; --resume runs what is missing")
    if done is not None:
        return dict(done)
    return {
        **spec.as_row(),
        "verdict": RunVerdict.ERROR.value,
        "ticks": 0,
        "failed_ticks": 0,
        "first_failure": f"could not run: {KILLED}",
        "wall_s": 0.0,
        "worker": "",
    }
