"""`--scheduler` and `--workers`: where a command's many runs run (a Dask cluster)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from harness.cluster.client import WORKER_WAIT_S
from harness.commands.arguments import (
    check_link_options,
    check_status_regex,
    given,
    positive,
    whole_number,
)
from harness.errors import ConfigError

if TYPE_CHECKING:
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings

workers = whole_number("workers", 1, 1_000)
# What a worker that runs scenarios itself (sweep, hunt) imports before it is forked.
WARM_WORKER = "harness.runner.warm_worker"


def add_cluster_options(parser: argparse.ArgumentParser, *, unit: str = "runs") -> None:
    """The embedded cluster's size, or an existing cluster's address (not both)."""
    group = parser.add_argument_group(f"where the {unit} run (Dask)")
    group.add_argument(
        "--scheduler",
        type=given("--scheduler"),
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
