"""`--scheduler` and `--workers`: where a command's many runs run (a Dask cluster)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from rich.console import Console

from harness.cluster.client import WORKER_WAIT_S
from harness.commands.arguments import (
    check_link_options,
    check_status_regex,
    not_empty,
    positive,
    whole_number,
)
from harness.errors import ConfigError, HarnessError, one_line
from harness.report.console_text import print_safe as say

if TYPE_CHECKING:
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings

workers = whole_number("workers", 1, 1_000)
# What a worker that runs scenarios itself (sweep, hunt) imports before it is forked.
WARM_WORKER = "harness.runner.warm_worker"
KILLED = "the worker running it died every time it was tried"


def add_cluster_options(parser: argparse.ArgumentParser, *, unit: str = "runs") -> None:
    """The embedded cluster's size, or an existing cluster's address (not both)."""
    group = parser.add_argument_group(f"where the {unit} run (Dask)")
    group.add_argument(
        "--scheduler",
        type=not_empty,
        metavar="ADDRESS",
        help="an existing Dask scheduler, e.g. tcp://host:8786 (default: an embedded cluster)",
    )
    group.add_argument(
        "--workers",
        type=workers,
        metavar="N",
        help=f"worker processes of the embedded cluster, {unit} at once (default: one per core)",
    )
    group.add_argument(
        "--worker-wait",
        type=positive("--worker-wait", 86_400),
        default=WORKER_WAIT_S,
        metavar="S",
        help="seconds the --scheduler cluster may take to offer its first worker, e.g. while "
        f"a batch queue starts one (default {WORKER_WAIT_S:g})",
    )


def describe_cluster(scheduler: str | None, workers: int | None) -> str:
    """Where the runs go, in words, for the command's opening line."""
    from harness.cluster.client import default_workers

    if scheduler is not None:
        return f"on the Dask cluster at {scheduler}"
    count = workers if workers is not None else default_workers()
    return f"on an embedded Dask cluster of {count} worker{'s' if count != 1 else ''}"


def checked_runs_options(args: argparse.Namespace, command: str) -> tuple[LinkOptions, RunSettings]:
    """The link options and judging settings every run of `command` (sweep, hunt) gets,
    checked before any cluster starts: the cluster options, no --domain-id (each run
    reserves its own), the node options, the status regex."""
    from harness.cluster.client import check_cluster_options
    from harness.runner.settings import RunSettings

    check_cluster_options(args.scheduler, args.workers)
    if args.domain_id is not None:
        raise ConfigError(f"--domain-id: every run of a {command} reserves a domain of its own")
    options = check_link_options(args)
    check_status_regex(args)
    judged = RunSettings(
        status_pattern=args.status_regex, warning_when_clear=args.warning_when_clear
    )
    return options, judged


@contextmanager
def runs_client(args: argparse.Namespace, console: Console, task_module: str) -> Iterator[Any]:
    """The Dask client a sweep's or hunt's runs go to (warm workers), its dashboard said."""
    from harness.cluster.client import dashboard, open_client

    with open_client(
        args.scheduler,
        args.workers,
        worker_wait=args.worker_wait,
        preload=(WARM_WORKER, task_module),
    ) as client:
        link = dashboard(client)
        if link:
            say(console, f"Dask dashboard: {link}")
        yield client


def run_result(future: Any, lost: str, then: str = "") -> Any | None:
    """A run's result; None when Dask gave up on it (it killed its worker every time). Any
    other loss (the scheduler went away) ends the command: "`lost` was lost to the ..."."""
    from distributed import KilledWorker

    try:
        return future.result()
    except KilledWorker:
        return None
    except Exception as err:  # noqa: BLE001 - lost to the cluster, not to the node
        why = f"{type(err).__name__}: {one_line(err)}"
        raise HarnessError(f"{lost} was lost to the Dask cluster ({why}){then}") from None
