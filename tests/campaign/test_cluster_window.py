"""harness.cluster.window on a real embedded Dask cluster: a worker holds only the task it
runs, so a task that kills its worker takes no other task down with it."""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Iterator
from typing import Any

import dask
import pytest
from distributed import Client, KilledWorker, LocalCluster

from harness.cluster.window import Window

pytestmark = [pytest.mark.slow, pytest.mark.timeout(180)]


@pytest.fixture
def client() -> Iterator[Any]:
    """Two one-thread workers; Dask gives up on a task the first time its worker dies."""
    strict = {
        "distributed.scheduler.allowed-failures": 0,
        "distributed.scheduler.worker-saturation": 1.0,
    }
    with dask.config.set(strict):
        cluster = LocalCluster(
            n_workers=2, threads_per_worker=1, dashboard_address=":0", silence_logs=40
        )
    with cluster, Client(cluster) as dask_client:
        yield dask_client


def _submit(client: Any, item: str) -> Any:
    """Each task a group of its own, as grade's students are (Dask hands those out at once)."""
    key = f"{item}-{uuid.uuid4().hex[:8]}"
    if item == "killer":
        return client.submit(os._exit, 9, key=key, pure=False)  # the worker process dies
    return client.submit(time.sleep, 0.5, key=key, pure=False)


def test_a_task_that_kills_its_worker_costs_only_itself(client: Any) -> None:
    items = ["killer", *(f"sleep{i}" for i in range(6))]
    window = Window(client, items, lambda item: _submit(client, item))
    outcomes: dict[str, str] = {}
    most = 0
    for index, future in window:
        most = max(most, max((len(keys) for keys in client.processing().values()), default=0))
        try:
            future.result()
        except KilledWorker:
            outcomes[items[index]] = "killed"
        else:
            outcomes[items[index]] = "done"
    assert outcomes == {"killer": "killed", **{f"sleep{i}": "done" for i in range(6)}}
    assert most <= 1  # never two tasks on one worker


def test_every_item_comes_back_once_with_its_index(client: Any) -> None:
    items = list(range(7))
    window = Window(client, items, lambda i: client.submit(abs, -i, pure=False))
    seen = [(index, future.result()) for index, future in window]
    assert sorted(seen) == [(i, i) for i in items]
    assert not window.running
