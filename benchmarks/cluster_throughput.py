"""How many runs a second `sweep` and `grade` get out of a Dask cluster, embedded or not.

    python benchmarks/cluster_throughput.py sweep [--workers N] [--external] [--seeds 10]
    python benchmarks/cluster_throughput.py grade [--workers N] [--external] [--students 30]
    python benchmarks/cluster_throughput.py overhead [--workers N] [--tasks 1000]

`sweep`: the reference node through 7 scenarios x 4 fault profiles x SEEDS.
`grade`: a class of STUDENTS single-file nodes (mostly correct; one reports
degrees, one hangs, one kills its worker) on every shipped scenario.
`--external` starts `dask scheduler` and N `dask worker` processes (as a lab
would, configured as docs/grading.md advises) and passes `--scheduler`;
otherwise the command's embedded cluster gets `--workers N`. `overhead`:
Dask's own cost per task, from trivial tasks on an embedded cluster.
Prints one line: runs, wall seconds, runs per second, and how many rows the
results hold by verdict (sweep) or by score (grade). Speed is measured
here, never asserted in tests (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import csv
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(REPO / "tests")]  # the tests' helpers
FAULTS = "clean,noisy,dropouts_nan,driver_rplidar_ros"
COMMAND = [sys.executable, "-m", "harness.cli"]


@contextlib.contextmanager
def external_cluster(workers: int) -> Iterator[str]:
    """`dask scheduler` and `workers` one-thread `dask worker`s, ready, stopped afterwards."""
    from dask_cluster import GRADING_ENV, dask_cluster
    from distributed import Client

    with dask_cluster(workers, nanny=True, env=GRADING_ENV) as (address, _):
        with Client(address, timeout=30) as client:
            client.wait_for_workers(workers, timeout=60)
        yield address


def make_class(folder: Path, students: int) -> None:
    """`students` single-file nodes: the last three degrees, hanging, worker-killing."""
    special = {
        students - 3: "angle_in_degrees",
        students - 2: "hangs",
        students - 1: "kills_worker",
    }
    from cluster_nodes import HANGS, KILLS_ITS_WORKER, variant_source

    for index in range(students):
        kind = special.get(index, "correct")
        source = {"hangs": HANGS, "kills_worker": KILLS_ITS_WORKER}.get(kind, variant_source(kind))
        (folder / f"s{index:03d}").mkdir(parents=True)
        (folder / f"s{index:03d}" / "lidar_node.py").write_text(source)


def timed(argv: list[str]) -> float:
    started = time.monotonic()
    done = subprocess.run(argv, capture_output=True, text=True, timeout=4 * 3600)
    wall = time.monotonic() - started
    if done.returncode not in (0, 1):
        sys.exit(f"failed ({done.returncode}): {done.stdout[-2000:]}{done.stderr[-2000:]}")
    return wall


def counted(out: Path, what: str) -> str:
    """The rows the command wrote, by verdict (sweep) or by passed scenarios (grade)."""
    name, column = ("results.csv", "verdict") if what == "sweep" else ("grades.csv", "passed")
    with open(out / name, encoding="utf-8", newline="") as handle:
        rows = list(csv.DictReader(handle))
    counts = collections.Counter(row[column] for row in rows)
    keys = {row.get("key") or row.get("student") for row in rows}
    parts = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    return f"{len(rows)} rows ({len(keys)} distinct): {parts}"


def overhead(workers: int, tasks: int) -> None:
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        client.gather(client.map(abs, range(-50, 0), pure=False))  # warm
        started = time.perf_counter()
        client.gather(client.map(abs, range(-tasks, 0), pure=False))
        wall = time.perf_counter() - started
    each = wall / tasks * 1000
    print(f"overhead: {tasks} trivial tasks on {workers} workers: {each:.2f} ms each")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("what", choices=("sweep", "grade", "overhead"))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--external", action="store_true")
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--students", type=int, default=30)
    parser.add_argument("--tasks", type=int, default=1000)
    args = parser.parse_args()
    if args.what == "overhead":
        overhead(args.workers, args.tasks)
        return
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        if args.what == "sweep":
            argv = [*COMMAND, "sweep", "--faults", FAULTS, "--seeds", str(args.seeds)]
            runs = 7 * 4 * args.seeds
        else:
            make_class(Path(tmp) / "class", args.students)
            argv = [*COMMAND, "grade", str(Path(tmp) / "class"), "--ready-timeout", "5"]
            runs = args.students
        argv += ["--out", str(out)]
        with contextlib.ExitStack() as stack:
            if args.external:
                argv += ["--scheduler", stack.enter_context(external_cluster(args.workers))]
            else:
                argv += ["--workers", str(args.workers)]
            wall = timed(argv)
        kind = "external" if args.external else "embedded"
        unit = "runs" if args.what == "sweep" else "students"
        print(
            f"{args.what}: {runs} {unit} on {args.workers} {kind} workers: "
            f"{wall:.1f} s, {runs / wall:.3f} {unit}/s; {counted(out, args.what)}"
        )


if __name__ == "__main__":
    main()
