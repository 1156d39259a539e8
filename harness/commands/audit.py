"""`fossbot-hil audit [SCENARIO ...]`: which typical mistakes the suite catches.

The library of Lab 07 mistakes (harness.audit.mutants) and a correct node
written the same way, through the scenarios on ``grade``'s Dask path. Exit 1
when a mistake survives (or the correct node fails a scenario).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from rich.console import Console

from harness.commands.arguments import (
    add_judging_options,
    add_link_option,
    check_status_regex,
    name_list,
    not_empty,
    whole_number,
)
from harness.commands.cluster_options import add_cluster_options, describe_cluster
from harness.errors import ConfigError
from harness.links.kinds import node_links
from harness.report.console_text import print_safe as say

NAME = "audit"
HELP = "run a library of typical node mistakes through the suite: which does it catch?"
REPEAT_SEED_BASE = 1000  # repeat k > 0 runs every scenario with seed 1000 + k


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scenarios",
        nargs="*",
        metavar="SCENARIO",
        help="scenario names or files (default: every shipped one)",
    )
    parser.add_argument(
        "--mutant",
        type=name_list,
        action="append",
        default=[],
        metavar="NAME[,NAME]",
        help="only these mistakes (repeatable; default: the whole library; see --list)",
    )
    parser.add_argument(
        "--list", action="store_true", help="list the mistakes in the library and exit"
    )
    parser.add_argument(
        "--repeat",
        type=whole_number("repeat", 1, 100),
        default=1,
        metavar="N",
        help="run each mistake N times, with the scenarios' own seeds and then seeds "
        f"{REPEAT_SEED_BASE + 1}.., and report verdicts that change (default 1)",
    )
    parser.add_argument(
        "--json", action="store_true", help="print one JSON object instead of the tables"
    )
    parser.add_argument(
        "--out",
        type=not_empty,
        default="audit",
        metavar="DIR",
        help="where audit.json and each mistake's run log go (default ./audit)",
    )
    add_link_option(parser)
    add_judging_options(parser)
    add_cluster_options(parser, unit="mistakes")
    for action in parser._actions:  # argparse has no public way to edit an added option
        if action.dest == "link":
            action.help = "ros2 (default), or a virtual board: rplidar, ldlidar"


def _chosen_mutants(items: list[list[str]]) -> list[str]:
    from harness.audit.mutants import MUTANTS, mutant_named

    names = [name for item in items for name in item]
    for name in names:
        mutant_named(name)  # ConfigError naming the known ones
    if len(set(names)) != len(names):
        raise ConfigError("--mutant: a mistake is named twice")
    return names or [m.name for m in MUTANTS]


def _list(console: Console) -> int:
    from harness.audit.mutants import MUTANTS

    width = max(len(m.name) for m in MUTANTS)
    for mutant in MUTANTS:
        say(console, f"{mutant.name:<{width}}  {mutant.mistake}")
    return 0


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.atomic_write import write_atomically
    from harness.audit.cache import audit_key, keep_audit
    from harness.audit.report import audit_json, exit_code, print_audit
    from harness.audit.suite_audit import audit_suite
    from harness.audit.task import AuditConfig, UnitResult
    from harness.cluster.client import check_cluster_options, open_client
    from harness.cluster.progress import add_task, task_progress
    from harness.commands.grade import selected_scenarios
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings, check_settings

    if args.list:
        return _list(console)
    check_cluster_options(args.scheduler, args.workers)
    if args.link not in node_links():
        raise ConfigError(f"--link {args.link}: audit runs nodes (use {', '.join(node_links())})")
    check_status_regex(args)
    mutants = _chosen_mutants(args.mutant)
    scenarios = selected_scenarios(args.scenarios)
    settings = RunSettings(
        threshold=args.threshold,
        status_pattern=args.status_regex,
        warning_when_clear=args.warning_when_clear,
    )
    check_settings(scenarios, settings)
    options = LinkOptions(scan_timeout=args.timeout)
    seeds: list[int | None] = [None] + [REPEAT_SEED_BASE + k for k in range(1, args.repeat)]
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ConfigError(f"--out {out}: {err.strerror or err}") from None
    config = AuditConfig(
        scenarios=tuple(s.name for s in scenarios),
        scenario_refs=tuple(s.source or s.name for s in scenarios),
        link=args.link,
        options=options,
        settings=settings,
        seeds=tuple(seeds),
        units_dir=out.resolve() / "mistakes",
    )
    shown = Console(file=sys.stderr) if args.json else console
    say(
        shown,
        f"audit: {len(mutants)} mistakes and the correct node through {len(scenarios)} "
        f"scenario{'s' if len(scenarios) != 1 else ''}, {args.repeat} time"
        f"{'s' if args.repeat != 1 else ''} each, over {args.link} "
        f"{describe_cluster(args.scheduler, args.workers)}",
    )
    started = time.monotonic()
    with (
        open_client(
            args.scheduler,
            args.workers,
            worker_wait=args.worker_wait,
            preload=("harness.audit.task",),  # each batch runs its nodes from its own process
        ) as client,
        task_progress(shown, "nodes", failed="did not finish") as progress,
    ):
        bar = add_task(progress, "nodes", len(mutants) + 1)

        broken = 0

        def unit_done(unit: UnitResult, running: int) -> None:
            nonlocal broken
            broken += unit.error is not None  # did not finish: the matrix says why
            progress.update(bar, advance=1, running=running, failed=broken)

        outcome = audit_suite(client, config, mutants, on_unit=unit_done)
    wall_s = time.monotonic() - started
    data = {**audit_json(outcome, repeat=args.repeat, seeds=seeds), "wall_s": round(wall_s, 1)}
    path = write_atomically(out / "audit.json", json.dumps(data, indent=2).encode())
    if not outcome.matrix.unit_errors:  # grade then warns from it without running it again
        keep_audit(audit_key(config, scenarios, mutants), data)
    if args.json:
        print(json.dumps(data, indent=2))
    else:
        print_audit(console, outcome)
        say(console, f"audited in {wall_s:.1f} s; wrote {path}")
    return exit_code(outcome.matrix)
