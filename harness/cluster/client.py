"""Opening and closing the Dask cluster a command runs its tasks on."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator, Sequence
from typing import Any

from harness.errors import OptionError, one_line
from harness.option_names import spoken

CONNECT_TIMEOUT_S = 10  # for an external scheduler to answer
WORKER_WAIT_S = 30.0  # for an external cluster without workers to get one (--worker-wait)
# Our tasks are long (a run, a student): a worker holds only the one it runs, so
# the next goes to whichever worker frees first, and a worker that dies takes no
# queued task down with it (Dask counts those as suspects, and gives up on a
# task suspected `allowed-failures` + 1 times).
ONE_TASK_PER_THREAD = 1.0
# The embedded cluster's workers are forked from one multiprocessing fork server that has
# imported Dask and what the command's tasks import (`preload`), instead of each spawning a
# fresh Python: about 1.2 CPU-s less a 2-worker cluster. (Workers that hung, forked or
# spawned, were waiting on a Fast DDS port a killed process had left half-made:
# harness.ros.shm_ports.)
WORKER_START = "forkserver"


def default_workers() -> int:
    """One worker per core: each run keeps a core busy (simulation) beside its node."""
    return max(1, len(os.sched_getaffinity(0)))


def check_cluster_options(scheduler: str | None, workers: int | None) -> None:
    """--scheduler and --workers: one cluster or the other (checked before a command starts)."""
    if scheduler is not None and workers is not None:
        raise OptionError("workers", "{workers} sizes the embedded cluster; not with {scheduler}")


@contextlib.contextmanager
def open_client(
    scheduler: str | None = None,
    workers: int | None = None,
    *,
    retries: int | None = None,
    worker_wait: float = WORKER_WAIT_S,
    preload: Sequence[str] = (),
    threads: bool = False,
) -> Iterator[Any]:
    """A Client on `scheduler`, or on a LocalCluster of `workers` processes that ends with it.

    `retries`: how often the embedded cluster runs a task again after its
    worker died under it (Dask's ``allowed-failures``, 3 by default); an
    external scheduler keeps its own setting. `worker_wait`: seconds an
    external cluster may take to offer its first worker. `preload`: modules the
    embedded cluster's workers import before they are forked (what the tasks need).
    `threads`: the embedded workers are threads of this process instead, for tasks
    that only wait on child processes which cannot reach this one (sandboxed
    students): no fork server or worker processes to start, about 1.2 s and 3 CPU-s
    less a class on 2 cores; a task that kills its worker would kill the command.
    """
    import dask
    from distributed import Client, LocalCluster

    check_cluster_options(scheduler, workers)
    if scheduler is not None:
        check_scheduler(scheduler)
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except Exception as err:  # noqa: BLE001 - anything here is the address's fault
            raise OptionError.saying(
                "scheduler", f"{scheduler}: cannot connect: {_said(err)}"
            ) from None
        with client:
            _wait_for_a_worker(client, scheduler, worker_wait)
            _speak_on_workers(client)
            yield client
        return
    count = workers if workers is not None else default_workers()
    limits: dict[str, float] = {"distributed.scheduler.worker-saturation": ONE_TASK_PER_THREAD}
    if retries is not None:
        limits["distributed.scheduler.allowed-failures"] = retries
    limits["distributed.worker.multiprocessing-method"] = WORKER_START
    with dask.config.set(limits):  # read by the scheduler and the nannies, which start here
        if not threads:
            _warm_worker_start(preload)
        cluster = LocalCluster(
            n_workers=count,
            threads_per_worker=1,
            processes=not threads,
            dashboard_address=":0",  # any free port: two commands may run at once
            silence_logs=40,  # errors only: the command reports progress itself
        )
    with cluster, Client(cluster) as client:
        _speak_on_workers(client)
        yield client


def _speak_on_workers(client: Any) -> None:
    """The workers word options as this process's caller does (worker_names)."""
    from harness.cluster.worker_names import OptionNames

    client.register_plugin(OptionNames(spoken()), name=OptionNames.name)


def _warm_worker_start(preload: Sequence[str]) -> None:
    """Have the fork server the workers start from import `preload` beside distributed
    (which imports the packages Dask's own list names). It starts with the first worker
    and lasts as long as this process: later clusters of the same process share it."""
    from distributed.utils import get_mp_context

    get_mp_context().set_forkserver_preload(["distributed", *preload])


def check_scheduler(address: str) -> None:
    """Ask `address` who it is, within CONNECT_TIMEOUT_S: a Dask scheduler, or a ConfigError.

    A Client alone waits for ever on a port that answers in another protocol
    (the dashboard's HTTP port, say), or reads its bytes as a huge frame.
    """
    import asyncio

    from distributed.core import rpc

    async def identity() -> Any:
        async with rpc(address, timeout=CONNECT_TIMEOUT_S) as scheduler:
            return await scheduler.identity()

    try:
        info = asyncio.run(asyncio.wait_for(identity(), CONNECT_TIMEOUT_S))
    except (TimeoutError, asyncio.TimeoutError):
        raise OptionError.saying(
            "scheduler",
            f"{address}: cannot connect: no Dask scheduler answered within {CONNECT_TIMEOUT_S} s",
        ) from None
    except Exception as err:  # noqa: BLE001 - a bad address, a refusal, another protocol
        raise OptionError.saying("scheduler", f"{address}: cannot connect: {_said(err)}") from None
    if not isinstance(info, dict) or info.get("type") != "Scheduler":
        raise OptionError.saying("scheduler", f"{address}: answers, but not as a Dask scheduler")


def _wait_for_a_worker(client: Any, address: str, wait_s: float) -> None:
    """A cluster without workers would wait for ever: give it `wait_s` to get one."""
    if client.nthreads():
        return
    try:
        client.wait_for_workers(1, timeout=wait_s)
    except (TimeoutError, OSError):
        raise OptionError.saying(
            "scheduler",
            f"{address}: no worker joined within {wait_s:g} s "
            f"(start one: dask worker {address} --nthreads 1)",
        ) from None


def _said(err: BaseException) -> str:
    """An error in one short line."""
    if isinstance(err, MemoryError):
        return "its answer is not Dask's protocol (is this the scheduler's port?)"
    return one_line(err)


def dashboard(client: Any) -> str | None:
    """The dashboard's address, when the cluster serves one."""
    with contextlib.suppress(Exception):
        link = client.dashboard_link
        return str(link) if link else None
    return None
