"""Opening and closing the Dask cluster a command runs its tasks on."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from typing import Any

from harness.errors import ConfigError

CONNECT_TIMEOUT_S = 10  # for an external scheduler to answer
# Our tasks are long (a run, a student): a worker holds only the one it runs, so
# the next goes to whichever worker frees first, and a worker that dies takes no
# queued task down with it (Dask counts those as suspects, and gives up on a
# task suspected `allowed-failures` + 1 times).
ONE_TASK_PER_THREAD = 1.0


def default_workers() -> int:
    """One worker per core: each run keeps a core busy (simulation) beside its node."""
    return max(1, len(os.sched_getaffinity(0)))


def check_cluster_options(scheduler: str | None, workers: int | None) -> None:
    """--scheduler and --workers: one cluster or the other (checked before a command starts)."""
    if scheduler is not None and workers is not None:
        raise ConfigError("--workers sizes the embedded cluster; not with --scheduler")


@contextlib.contextmanager
def open_client(
    scheduler: str | None = None, workers: int | None = None, *, retries: int | None = None
) -> Iterator[Any]:
    """A Client on `scheduler`, or on a LocalCluster of `workers` processes that ends with it.

    `retries`: how often the embedded cluster runs a task again after its
    worker died under it (Dask's ``allowed-failures``, 3 by default); an
    external scheduler keeps its own setting.
    """
    import dask
    from distributed import Client, LocalCluster

    check_cluster_options(scheduler, workers)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as err:
            raise ConfigError(f"--scheduler {scheduler}: cannot connect: {err}") from None
        with client:
            yield client
        return
    count = workers if workers is not None else default_workers()
    limits: dict[str, float] = {"distributed.scheduler.worker-saturation": ONE_TASK_PER_THREAD}
    if retries is not None:
        limits["distributed.scheduler.allowed-failures"] = retries
    with dask.config.set(limits):  # read by the scheduler, which starts here
        cluster = LocalCluster(
            n_workers=count,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # any free port: two commands may run at once
            silence_logs=40,  # errors only: the command reports progress itself
        )
    with cluster, Client(cluster) as client:
        yield client


def dashboard(client: Any) -> str | None:
    """The dashboard's address, when the cluster serves one."""
    with contextlib.suppress(Exception):
        link = client.dashboard_link
        return str(link) if link else None
    return None
