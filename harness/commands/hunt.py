"""`fossbot-hil hunt`: search generated scenarios for one the node fails, shrink it to the
simplest that still fails, and leave it ready to add to a suite."""

from __future__ import annotations

import argparse
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console

from harness.atomic_write import write_atomically
from harness.commands.arguments import (
    add_judging_options,
    add_link_option,
    add_node_options,
    not_empty,
    positive,
    seed,
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
from harness.links.kinds import either, link_kind, link_names
from harness.report.console_text import print_safe as say
from harness.safe_text import for_csv, shown

if TYPE_CHECKING:
    from harness.hunt.search import Hunt, HuntPlan
    from harness.hunt.space import Candidate
    from harness.hunt.task import Outcome
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings

NAME = "hunt"
HELP = "search generated scenarios for the simplest one the node fails"
DESCRIPTION = (
    "Search generated scenarios (an obstacle, a motion, the LIDAR preset, the driver's "
    "no-return convention, a sensor fault, the threshold) for one the node fails, guided by "
    "how close its answers come to failing; shrink it to the simplest that still fails the "
    "same way and write it to DIR as a scenario file with its explanation, recording, plot "
    "and the command that reproduces it. Exit 1 when one was found, 0 when none was within "
    "the budget. See docs/hunt.md."
)
DEFAULT_BUDGET = 200
DEFAULT_BATCH = 4
DEFAULT_SHRINK_BUDGET = 60
REPRODUCE_TIMEOUT_S = 180.0  # the counterexample's own run, node start-up included

#: Options a reproducing `fossbot-hil run` repeats when they were given (by dest).
RUN_OPTIONS = (
    "link", "node", "package", "executable", "workspace", "param", "threshold_param", "scan_topic",
    "status_topic", "warning_topic", "ready_timeout", "ros_network", "realtime", "status_regex",
    "warning_when_clear", "timeout",
)  # fmt: skip
OUTPUTS = (  # what a hunt writes in DIR: an earlier hunt's are removed first
    "hunt.json", "runs.csv", "counterexample.yaml", "explanation.txt", "reproduce.sh",
    "counterexample.mcap", "counterexample.png", "run",
)  # fmt: skip


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--budget",
        type=whole_number("budget", 1, 100_000),
        default=DEFAULT_BUDGET,
        metavar="RUNS",
        help=f"search runs at most (default {DEFAULT_BUDGET}; confirming and shrinking a "
        "failure take more)",
    )
    parser.add_argument(
        "--time",
        type=positive("--time", 7 * 86_400),
        metavar="S",
        help="seconds to search at most, checked between batches (default: no limit)",
    )
    parser.add_argument(
        "--seed",
        type=seed,
        default=0,
        help="the search's seed: the same seed, the same hunt (default 0)",
    )
    parser.add_argument(
        "--batch",
        type=whole_number("batch", 1, 1000),
        default=DEFAULT_BATCH,
        metavar="N",
        help=f"runs proposed and judged together (default {DEFAULT_BATCH}); the hunt depends "
        "on it, not on the number of workers",
    )
    parser.add_argument(
        "--shrink-budget",
        type=whole_number("shrink budget", 0, 10_000),
        default=DEFAULT_SHRINK_BUDGET,
        metavar="RUNS",
        help=f"runs shrinking a failure may take (default {DEFAULT_SHRINK_BUDGET})",
    )
    parser.add_argument(
        "--out",
        type=not_empty,
        default="hunt",
        metavar="DIR",
        help="where the counterexample and hunt.json go (default ./hunt)",
    )
    add_link_option(parser)
    add_judging_options(parser, threshold=False)  # the threshold is searched
    add_cluster_options(parser)
    add_node_options(parser, domain_help=argparse.SUPPRESS)  # refused: each run reserves one


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.hunt.search import HuntPlan, optuna_module

    kind = link_kind(args.link)
    if kind.serial_line:
        over = either([name for name in link_names() if not link_kind(name).serial_line])
        raise ConfigError(f"--link {args.link}: hunt runs nodes over {over}")
    options, judged = checked_runs_options(args, "hunt")
    if kind.runs_node:
        from harness.links.node_start import node_command

        node_command(options)  # a missing node program is exit 2 now, not a failed run
    optuna_module()  # exit 2 now if it is missing, not after the cluster started
    plan = HuntPlan(args.budget, args.time, args.seed, args.batch, args.shrink_budget)
    out = Path(args.out)
    _clear(out)
    limit = f", {args.time:g} s at most" if args.time else ""
    say(
        console,
        f"hunt: up to {plan.budget} runs{limit}, seed {plan.seed}, batches of {plan.batch}, "
        f"{describe_cluster(args.scheduler, args.workers)}; results in {out}",
    )
    result = _search(console, args, plan, options, judged)  # runs.csv written as it goes
    if result.found is None:
        _write_summary(out, args, result, None, None)
        for line in _nothing_found(result):
            say(console, line)
        return 0
    command = _reproduce_command(args, out / "counterexample.yaml")
    _write_counterexample(out, result, plan.seed, command)
    reproduced = _reproduce(out, command, args)
    _write_summary(out, args, result, command, reproduced)
    for line in _found_lines(result, out, command, reproduced):
        say(console, line)
    return 1


def _search(
    console: Console,
    args: argparse.Namespace,
    plan: HuntPlan,
    options: LinkOptions,
    judged: RunSettings,
) -> Hunt:
    """The hunt on the cluster, with a progress bar of its search runs; runs.csv is
    rewritten after every batch, so an interrupted hunt keeps its runs."""
    from harness.cluster.progress import add_task, task_progress
    from harness.hunt.search import hunt
    from harness.hunt.space import placed, robot_footprint

    robot = robot_footprint()

    def feasible(candidate: Candidate) -> Candidate | None:
        from harness.hunt.task import scenario_of

        candidate = placed(candidate, robot)
        try:
            scenario_of(candidate, seed=plan.seed)
        except ConfigError:
            return None
        return candidate

    with runs_client(args, console, "harness.hunt.task") as client:

        def run_batch(candidates: list[Candidate]) -> list[Outcome]:
            return _run_on(client, candidates, plan.seed, args.link, options, judged)

        with task_progress(console, "runs", failed="failed") as progress:
            bar = add_task(progress, "runs", plan.budget)

            def on_batch(result: Hunt) -> None:
                failed = sum(1 for o in result.runs if o.assessment and o.assessment.failed)
                progress.update(bar, completed=len(result.runs), failed=failed, running=0)
                _write_runs(Path(args.out), result)

            return hunt(plan, run_batch, feasible, on_batch)


def _run_on(
    client: Any,
    candidates: list[Candidate],
    run_seed: int,
    link_name: str,
    options: LinkOptions,
    judged: RunSettings,
) -> list[Outcome]:
    """Each candidate's outcome, in order; a run Dask gave up on is an outcome too."""
    from harness.hunt.task import Outcome, run_candidate

    futures = [
        client.submit(run_candidate, c, run_seed, link_name, options, judged, pure=False)
        for c in candidates
    ]
    outcomes = [run_result(future, "hunt stopped: a run") for future in futures]
    return [
        Outcome(candidate, None, 0.0, KILLED) if outcome is None else outcome
        for candidate, outcome in zip(candidates, outcomes, strict=True)
    ]


def _clear(out: Path) -> None:
    """Remove an earlier hunt's outputs from `out` (nothing else), so a hunt that finds
    nothing leaves no old counterexample behind."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out}: not a folder")
    for name in OUTPUTS:
        path = out / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()


def _reproduce_command(args: argparse.Namespace, scenario: Path) -> list[str]:
    """`fossbot-hil run SCENARIO` with the node and judging options the hunt was given."""
    command = ["fossbot-hil", "run", str(scenario)]
    typed = getattr(args, "given", frozenset())
    for dest in RUN_OPTIONS:
        if dest not in typed:
            continue
        flag = "--" + dest.replace("_", "-")
        value = getattr(args, dest)
        if value is True:
            command.append(flag)
        elif isinstance(value, list):
            for item in value:
                command += [flag, str(item)]
        elif value not in (None, False):
            command += [flag, f"{value:g}" if isinstance(value, float) else str(value)]
    return command


def _write_counterexample(out: Path, result: Hunt, run_seed: int, command: list[str]) -> None:
    """counterexample.yaml (commented with where it came from) and reproduce.sh."""
    import yaml

    from harness.hunt.space import robot_footprint, scenario_document

    assert result.shrunk is not None and result.shrunk.assessment is not None
    shrunk = result.shrunk
    kinds = ", ".join(shrunk.assessment.kinds)
    description = f"Found by fossbot-hil hunt (seed {run_seed}): fails on {kinds}"
    document = scenario_document(
        shrunk.candidate, robot_footprint(), description=description, seed=run_seed
    )
    header = "".join(
        f"# {line}\n"
        for line in (
            f"Found by `fossbot-hil hunt --seed {run_seed}` in run {len(result.runs)} "
            f"and shrunk in {len(result.shrink_steps)} steps: {shrunk.candidate.describe()}.",
            # the node's words, one escaped line: a line break would end the comment
            f"First failure (tick {shrunk.assessment.tick}): "
            + shown(shrunk.assessment.first_failure, 300),
            "Reproduce: " + shlex.join(command),
        )
    )
    text = header + yaml.safe_dump(document, sort_keys=False, allow_unicode=True)
    write_atomically(out / "counterexample.yaml", text.encode())
    script = (
        "#!/bin/sh\n# The counterexample, run as the hunt ran it.\n" + shlex.join(command) + "\n"
    )
    path = write_atomically(out / "reproduce.sh", script.encode())
    path.chmod(0o755)


def _reproduce(out: Path, command: list[str], args: argparse.Namespace) -> bool | None:
    """Run the reproducing command (with a report folder) and keep what it says: True when
    it failed as it should, False when it passed, None when it could not say."""
    argv = [
        sys.executable,
        "-c",
        "import sys; from harness.cli import entry; sys.argv[0] = 'fossbot-hil'; entry()",
        *command[1:],
        "--out",
        str(out / "run"),
    ]
    env = {**os.environ, "NO_COLOR": "1", "COLUMNS": "100", "TERM": "dumb"}
    try:
        done = subprocess.run(
            argv,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            timeout=REPRODUCE_TIMEOUT_S + args.ready_timeout,
            env=env,
            check=False,
        )
    except subprocess.TimeoutExpired:
        write_atomically(out / "explanation.txt", b"the reproducing run did not end in time\n")
        return None
    text = done.stdout.decode(errors="replace") + done.stderr.decode(errors="replace")
    write_atomically(out / "explanation.txt", text.encode())
    for suffix in (".mcap", ".png"):
        made = out / "run" / "scenarios" / f"counterexample{suffix}"
        if made.is_file():
            shutil.copyfile(made, out / f"counterexample{suffix}")
    return {1: True, 0: False}.get(done.returncode)


def _write_runs(out: Path, result: Hunt) -> None:
    """runs.csv: every search run, its candidate and how it went."""
    import csv
    import io

    rows = [
        {"run": index + 1, **{k: for_csv(v) if isinstance(v, str) else v for k, v in row.items()}}
        for index, row in enumerate(o.as_row() for o in result.runs)
    ]
    if not rows:
        return
    buffer = io.StringIO()
    columns = list(dict.fromkeys(name for row in rows for name in row))
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    write_atomically(out / "runs.csv", buffer.getvalue().encode())


def _write_summary(
    out: Path,
    args: argparse.Namespace,
    result: Hunt,
    command: list[str] | None,
    reproduced: bool | None,
) -> None:
    """hunt.json: the search's size and the counterexample, for scripts."""
    import json

    found, shrunk, best = result.found, result.shrunk, result.best
    summary: dict[str, Any] = {
        "found": found is not None,
        "seed": args.seed,
        "budget": args.budget,
        "batch": args.batch,
        "runs": len(result.runs),
        "confirm_runs": result.confirm_runs,
        "shrink_runs": result.shrink_runs,
        "restarts": result.restarts,
        "stopped_by": result.stopped_by,
        "seconds": round(result.elapsed_s, 2),
        "runs_per_s": round(result.total_runs / result.elapsed_s, 3) if result.elapsed_s else None,
        "flaky": [o.as_row() for o in result.flaky],
        "problems": sum(1 for o in result.runs if o.assessment is None),
        "closest": best.as_row() if best is not None else None,
        "found_at_run": len(result.runs) if found is not None else None,
        "original": found.as_row() if found is not None else None,
        "counterexample": shrunk.as_row() if shrunk is not None else None,
        "shrink_steps": result.shrink_steps,
        "command": shlex.join(command) if command else None,
        "reproduced": reproduced,
    }
    write_atomically(out / "hunt.json", (json.dumps(summary, indent=2) + "\n").encode())


def _nothing_found(result: Hunt) -> list[str]:
    runs = len(result.runs)
    why = "the time limit" if result.stopped_by == "time" else "the budget"
    lines = [
        f"no failing scenario in {runs} run{'s' if runs != 1 else ''} "
        f"({result.elapsed_s:.0f} s, stopped by {why}, {result.restarts} restarts)"
    ]
    best = result.best
    if best is not None and best.assessment is not None:
        lines.append(f"closest (margin {best.assessment.margin:.3f}): {best.candidate.describe()}")
    if result.flaky:
        lines.append(
            f"{len(result.flaky)} failure(s) did not fail again when re-run (flaky): "
            f"{result.flaky[0].candidate.describe()}"
        )
    return lines


def _found_lines(result: Hunt, out: Path, command: list[str], reproduced: bool | None) -> list[str]:
    assert result.found is not None and result.shrunk is not None
    shrunk = result.shrunk.assessment
    assert shrunk is not None
    steps = "; ".join(result.shrink_steps) or "nothing simpler failed the same way"
    verdict = {
        True: "it fails again as a scenario file",
        False: "WARNING: it PASSED when run from its file (a failure of timing? see "
        "explanation.txt)",
        None: "its reproducing run could not say (see explanation.txt)",
    }[reproduced]
    return [
        f"found a failing scenario in run {len(result.runs)} "
        f"({result.elapsed_s:.0f} s); shrunk in {result.shrink_runs} runs: {steps}",
        f"counterexample: {result.shrunk.candidate.describe()}",
        f"fails on {', '.join(shrunk.kinds)} at tick {shrunk.tick}: "
        + shrunk.first_failure.replace("\n", " ")[:400],
        f"{verdict}; wrote {out / 'counterexample.yaml'}, explanation.txt, the recording and "
        "the plot",
        "reproduce: " + shlex.join(command),
    ]
