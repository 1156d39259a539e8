"""`fossbot-hil sweep` on real Dask clusters: the embedded default, and one started with
Dask's own `dask scheduler` / `dask worker` commands, one worker killed (-9) mid-sweep
in each.

Every run must be in the results exactly once, with the verdicts a one-machine
sweep of the same seeds gives (four runs of a short wall approach: clean and noisy,
two seeds). A node that hangs, and one that kills its worker every time, each cost
their own runs only, as ERROR rows.
"""

from __future__ import annotations

import contextlib
import csv
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from cluster_nodes import HANGS, KILLS_ITS_WORKER
from command_line import COMMAND, fossbot_hil
from dask_cluster import children, dask_cluster
from short_scenarios import NEAR_WALL

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]


@pytest.fixture(scope="module")
def sweep_args(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """The sweep every cluster runs: 4 runs (clean and noisy, seeds 0 and 1)."""
    scenario = tmp_path_factory.mktemp("scenario") / "near_wall.yaml"
    scenario.write_text(NEAR_WALL)
    return [
        *("sweep", "--scenario", str(scenario), "--faults", "clean,noisy", "--seed-count", "2"),
        *("--timeout", "5"),  # a generous per-scan deadline: a busy machine is not late
    ]


def _rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "results.csv", encoding="utf-8", newline="") as handle:
        return list(csv.DictReader(handle))


def _verdicts(rows: list[dict[str, str]]) -> dict[str, tuple[str, str, str]]:
    return {r["key"]: (r["verdict"], r["ticks"], r["failed_ticks"]) for r in rows}


@pytest.fixture(scope="module")
def one_machine(
    sweep_args: list[str], tmp_path_factory: pytest.TempPathFactory
) -> dict[str, tuple[str, str, str]]:
    """The verdicts of the sweep on one worker: what every cluster must give."""
    out = tmp_path_factory.mktemp("one") / "sweep"
    done = fossbot_hil(*sweep_args, "--workers", "1", "--out", str(out), timeout=240)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    expected = _verdicts(_rows(out))
    assert len(expected) == 4
    return expected


def _local_workers(pid: int) -> list[int]:
    """The embedded cluster's worker processes: the children of the multiprocessing fork
    server the command started (or the command's spawned children)."""
    found = []
    for child in children(pid):
        try:
            command = Path(f"/proc/{child}/cmdline").read_bytes()
        except OSError:
            continue
        if b"multiprocessing.forkserver" in command:
            with contextlib.suppress(OSError):
                found += children(child)
        elif b"spawn_main" in command:
            found.append(child)
    return found


def test_an_external_cluster_loses_nothing_when_a_worker_is_killed(
    sweep_args: list[str], one_machine: dict[str, tuple[str, str, str]], tmp_path: Path
) -> None:
    expected = one_machine
    out = tmp_path / "cluster"
    with dask_cluster(2, nanny=False) as (address, workers):
        sweep = subprocess.Popen(
            [*COMMAND, *sweep_args, "--scheduler", address, "--out", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and sweep.poll() is None:
            if (out / "results.csv").exists() and len(_rows(out)) >= 1:
                os.kill(workers[0].pid, signal.SIGKILL)  # mid-sweep: the others are running
                break
            time.sleep(0.05)
        output, _ = sweep.communicate(timeout=240)
    assert sweep.returncode in (0, 1), output
    rows = _rows(out)
    keys = [r["key"] for r in rows]
    assert len(keys) == len(set(keys)) == 4, output  # every run, exactly once
    assert _verdicts(rows) == expected
    assert (out / "summary.txt").read_text().strip()


def test_the_embedded_default_loses_nothing_when_a_worker_is_killed_and_resumes(
    sweep_args: list[str], one_machine: dict[str, tuple[str, str, str]], tmp_path: Path
) -> None:
    out = tmp_path / "sweep"
    sweep = subprocess.Popen(
        [*COMMAND, *sweep_args, "--out", str(out)],  # no --workers: one per core
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    killed = None
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and sweep.poll() is None:
        if (out / "results.csv").exists() and len(_rows(out)) >= 1:
            workers = _local_workers(sweep.pid)
            if workers:
                killed = workers[0]
                os.kill(killed, signal.SIGKILL)  # mid-sweep: its run is retried elsewhere
                break
        time.sleep(0.05)
    output, _ = sweep.communicate(timeout=240)
    assert killed is not None, output
    assert sweep.returncode in (0, 1), output
    assert "on an embedded Dask cluster of" in output and "Dask dashboard: http" in output
    rows = _rows(out)
    keys = [r["key"] for r in rows]
    assert len(keys) == len(set(keys)) == 4, output  # every run, exactly once
    assert _verdicts(rows) == one_machine

    kept = (out / "results.csv").read_text().splitlines()[:4]  # header and three rows
    (out / "results.csv").write_text("\n".join(kept) + "\n")
    again = fossbot_hil(*sweep_args, "--workers", "1", "--out", str(out), "--resume", timeout=240)
    assert "(3 done already)" in again.stdout, again.stdout + again.stderr
    assert _verdicts(_rows(out)) == one_machine


def _node(tmp_path: Path, source: str) -> str:
    script = tmp_path / "node.py"
    script.write_text(source)
    return f"{sys.executable} {script}"


def test_a_hanging_node_costs_only_its_runs(tmp_path: Path) -> None:
    """A node that never comes up and ignores SIGTERM: each run ends at its deadline, and
    the one worker goes on to the next."""
    out = tmp_path / "sweep"
    done = fossbot_hil(
        *("sweep", "--scenario", "approach_wall", "--seed-count", "2", "--workers", "1"),
        *("--node", _node(tmp_path, HANGS), "--ready-timeout", "1", "--out", str(out)),
        timeout=240,
    )
    assert done.returncode == 1, done.stdout + done.stderr
    rows = _rows(out)
    assert [r["verdict"] for r in rows] == ["ERROR", "ERROR"], rows
    assert all(r["first_failure"] for r in rows), rows


def test_a_node_that_kills_its_worker_every_time_is_an_error_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Dask gives up on the run after its retries; the sweep writes its row and ends."""
    # One retry, as docs/grading.md advises a lab's scheduler (Dask's default is 3): each
    # try costs a worker.
    monkeypatch.setenv("DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES", "1")
    out = tmp_path / "sweep"
    done = fossbot_hil(
        *("sweep", "--scenario", "approach_wall", "--workers", "1"),
        *("--node", _node(tmp_path, KILLS_ITS_WORKER), "--out", str(out)),
        timeout=240,
    )
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    [row] = _rows(out)
    assert row["verdict"] == "ERROR"
    assert "the worker running it died every time" in row["first_failure"], row


@pytest.fixture
def silent_port() -> Iterator[int]:
    """A port that takes connections and never answers (not a Dask scheduler)."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        yield int(server.getsockname()[1])


def test_a_port_that_is_no_scheduler_is_refused_in_bounded_time(
    silent_port: int, tmp_path: Path
) -> None:
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "results.csv").write_text("an earlier campaign\n")
    address = f"tcp://127.0.0.1:{silent_port}"
    done = fossbot_hil("sweep", "--out", str(out), "--scheduler", address, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "no Dask scheduler answered within" in lines[0], done.stderr
    assert (out / "results.csv").read_text() == "an earlier campaign\n"  # untouched


def test_a_cluster_without_workers_is_refused_in_bounded_time(tmp_path: Path) -> None:
    with dask_cluster(0, nanny=False) as (address, _):
        out = ["--out", str(tmp_path / "s")]
        done = fossbot_hil("sweep", *out, "--scheduler", address, "--worker-wait", "2")
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "no worker joined within 2 s" in lines[0], done.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["--seed-count", "0"], "--seed-count"),
        (["--thresholds", "0.3,-1"], "threshold"),
        (["--scenario", "no_such_scenario"], "unknown scenario"),
        (["--faults", "no_such_profile"], "no_such_profile"),
        (["--domain-id", "5"], "--domain-id"),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers"),
        (["--scheduler", "notanaddress"], "--scheduler notanaddress: cannot connect"),
        (["--seeds", "ten"], "--seeds"),  # the old name: still parsed, still checked
        (["--worker-wait", "0"], "--worker-wait must be a positive number"),
        (["--vary", "spd=1"], "NAME one of start_dx, start_dy"),
        (["--vary", "speed=0"], "speed: a level is a number > 0"),
        (["--vary", "speed=1", "--vary", "speed=2"], "--vary speed: given twice"),
        (["--scenario", "reverse_to_wall", "--vary", "wall_distance=1"], "straight ahead"),
        (["--scenario", "approach_wall", "--vary", "speed=50"], "--vary speed=50: "),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args: list[str], message: str, tmp_path: Path) -> None:
    done = fossbot_hil("sweep", "--out", str(tmp_path / "s"), *args, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], done.stderr


def test_generated_variations_are_factors_with_a_column_each(tmp_path: Path) -> None:
    """Two wall distances of approach_wall: one row each, the level in its own column,
    and the same rows in results.parquet with typed columns."""
    out = tmp_path / "sweep"
    done = fossbot_hil(
        "sweep",
        "--scenario",
        "approach_wall",
        "--vary",
        "wall_distance=0.4,1.5",
        "--workers",
        "1",
        "--timeout",
        "5",
        "--parquet",
        "--out",
        str(out),
        timeout=240,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    rows = _rows(out)
    assert [(r["wall_distance"], r["verdict"]) for r in rows] == [("0.4", "PASS"), ("1.5", "PASS")]
    assert int(rows[0]["ticks"]) < int(rows[1]["ticks"])  # the nearer wall is reached sooner
    parquet = pytest.importorskip("pyarrow.parquet")
    table = parquet.read_table(out / "results.parquet").to_pylist()
    assert [r["wall_distance"] for r in table] == [0.4, 1.5]
