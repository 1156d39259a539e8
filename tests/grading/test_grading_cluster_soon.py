"""The cluster `grade` starts in the background (harness.cluster.soon), on real Dask: its
client works from the thread that asks for it, a start that fails is raised there, and
closing leaves no cluster behind, used or not."""

from __future__ import annotations

import threading

import pytest
from dask_cluster import free_port

from harness.cluster.soon import client_soon
from harness.errors import ConfigError

pytestmark = [pytest.mark.timeout(120)]


def _double(x: int) -> int:
    return 2 * x


def _cluster_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name == "fossbot-hil-cluster"]


def test_the_client_opened_in_the_background_runs_tasks_and_closes() -> None:
    with client_soon(workers=1, retries=1) as soon:
        client = soon.client()
        assert client.submit(_double, 21, pure=False).result(timeout=60) == 42
        assert client.status == "running"
    assert client.status == "closed"  # closed by the thread that opened it
    assert _cluster_threads() == []


def test_a_cluster_never_asked_for_is_closed_too() -> None:
    with client_soon(workers=1) as soon:
        pass
    assert soon._client is None or soon._client.status == "closed"
    assert _cluster_threads() == []


def test_a_scheduler_that_does_not_answer_is_a_config_error_where_the_client_is_asked() -> None:
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    with client_soon(scheduler=address) as soon:
        with pytest.raises(ConfigError, match="cannot connect"):
            soon.client()
    assert _cluster_threads() == []
