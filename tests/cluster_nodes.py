"""Single-file student nodes for grading and sweeping on a cluster: a variant of the
student node, one that hangs, one that kills its Dask worker (tests/grading,
tests/campaign, benchmarks/cluster_throughput.py)."""

from __future__ import annotations

from pathlib import Path

STUDENT_NODE = Path(__file__).resolve().parent / "ros" / "student_node.py"


def variant_source(variant: str) -> str:
    """A student_node variant as one self-contained file: what a student hands in (a
    sandboxed node sees its own folder only, never the test suite's files)."""
    return f"import sys\n\nsys.argv[1:1] = [{variant!r}]\n" + STUDENT_NODE.read_text()


HANGS = (
    "import signal\nimport time\n\n"
    "signal.signal(signal.SIGTERM, signal.SIG_IGN)  # and never comes up\n"
    "while True:\n    time.sleep(1)\n"
)
# Walks up its ancestors to the Dask worker process (the embedded cluster's, forked by
# multiprocessing's fork server; a nanny's spawned child; or a `dask worker --no-nanny`)
# and kills it, as a node gone badly wrong might.
KILLS_ITS_WORKER = """\
import os
import signal

WORKER_MARKS = (b"multiprocessing.forkserver", b"spawn_main", b"dask_worker")
pid = os.getppid()
while pid > 1:
    with open(f"/proc/{pid}/cmdline", "rb") as handle:
        command = handle.read().replace(b"\\0", b" ")
    if any(mark in command for mark in WORKER_MARKS):
        os.kill(pid, signal.SIGKILL)
        break
    with open(f"/proc/{pid}/stat", "rb") as handle:
        pid = int(handle.read().rsplit(b")", 1)[1].split()[1])
"""
