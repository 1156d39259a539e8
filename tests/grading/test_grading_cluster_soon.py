"""The cluster `grade` starts in the background (harness.cluster.soon), on real Dask: its
client works from the thread that asks for it, a start that fails is raised there,
closing leaves no cluster behind, used or not, and workers that are threads of the
command still keep a judge's slot each."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest
from dask_cluster import free_port

from harness.cluster.soon import client_soon
from harness.errors import ConfigError
from harness.grading.grade import GradeConfig, _slot
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

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


# Both tasks at once, so each is on a worker of its own (one task a worker at a time): the
# workers are threads of this process, so they meet here; two on one worker never would.
_BOTH_RUNNING = threading.Barrier(2)


def _where_graded(config: GradeConfig) -> tuple[int, str]:
    _BOTH_RUNNING.wait(timeout=30)
    return os.getpid(), _slot(config).root.name


def test_workers_as_threads_share_the_process_but_each_keeps_a_slot_of_its_own(
    tmp_path: Path,
) -> None:
    """A sandboxed grading's embedded workers are threads of the command: its judges and
    their slots are still one a worker (named by the Dask worker, not the process)."""
    config = GradeConfig((), (), "ros2", LinkOptions(), RunSettings(), tmp_path, 1.0, 1.0)
    with client_soon(workers=2, threads=True) as soon:
        client = soon.client()
        tasks = [client.submit(_where_graded, config, pure=False) for _ in range(2)]
        places = [task.result(timeout=60) for task in tasks]
    assert {pid for pid, _ in places} == {os.getpid()}
    assert len({slot for _, slot in places}) == 2, places
    assert _cluster_threads() == []
