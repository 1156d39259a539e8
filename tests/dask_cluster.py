"""A Dask cluster started with Dask's own `dask scheduler` / `dask worker` commands, as a
lab starts one: for the cluster tests and benchmarks/cluster_throughput.py."""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path

SCHEDULER = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
# What docs/grading.md advises a lab's scheduler for grading (the embedded cluster's).
GRADING_ENV = {
    "DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "1",
    "DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION": "1.0",
}


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def children(pid: int) -> list[int]:
    """The processes `pid` started (a nanny's worker)."""
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(OSError):
            found += [int(p) for p in (task / "children").read_text().split()]
    return found


@contextlib.contextmanager
def dask_cluster(
    workers: int, *, nanny: bool, env: Mapping[str, str] | None = None
) -> Iterator[tuple[str, list[subprocess.Popen[bytes]]]]:
    """A scheduler and `workers` single-threaded workers on localhost, all stopped
    afterwards. Without nannies a killed worker stays dead; with them it comes back.
    Yields the address and the worker (or nanny) processes."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    quiet = {
        "stdout": subprocess.DEVNULL,
        "stderr": subprocess.DEVNULL,
        "env": {**os.environ, **(env or {})},
    }
    scheduler = subprocess.Popen(
        [*SCHEDULER, "--host", "127.0.0.1", "--port", str(port), "--dashboard-address", ":0"],
        **quiet,
    )
    extra = [] if nanny else ["--no-nanny"]
    started = [
        subprocess.Popen([*WORKER, address, "--nthreads", "1", *extra], **quiet)
        for _ in range(workers)
    ]
    try:
        yield address, started
    finally:
        for process in [*started, scheduler]:
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
        for process in [*started, scheduler]:
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=10)
