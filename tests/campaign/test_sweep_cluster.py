"""`fossbot-hil sweep` on real Dask clusters: an embedded one, and one started with Dask's
own `dask scheduler` / `dask worker` commands, one worker killed (-9) mid-sweep.

Every run must be in the results exactly once, with the verdicts a one-machine
sweep of the same seeds gives.
"""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from command_line import COMMAND, fossbot_hil
from dask_cluster import dask_cluster

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]

SWEEP = [
    "sweep",
    "--scenario",
    "approach_wall,obstacle_at_side",
    "--faults",
    "clean,noisy",
    "--seeds",
    "2",
    "--timeout",
    "5",  # a generous per-scan deadline: a busy machine must not turn into a late answer
]


def _rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "results.csv", encoding="utf-8", newline="") as handle:
        return list(csv.DictReader(handle))


def _verdicts(rows: list[dict[str, str]]) -> dict[str, tuple[str, str, str]]:
    return {r["key"]: (r["verdict"], r["ticks"], r["failed_ticks"]) for r in rows}


def test_an_external_cluster_loses_nothing_when_a_worker_is_killed(tmp_path: Path) -> None:
    one_machine = tmp_path / "one"
    done = fossbot_hil(*SWEEP, "--workers", "1", "--out", str(one_machine), timeout=240)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    expected = _verdicts(_rows(one_machine))
    assert len(expected) == 8

    out = tmp_path / "cluster"
    with dask_cluster(2, nanny=False) as (address, workers):
        sweep = subprocess.Popen(
            [*COMMAND, *SWEEP, "--scheduler", address, "--out", str(out)],
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
    assert len(keys) == len(set(keys)) == 8, output  # every run, exactly once
    assert _verdicts(rows) == expected
    assert (out / "summary.txt").read_text().strip()


def test_the_embedded_cluster_resumes_what_is_missing(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    first = fossbot_hil(*SWEEP, "--workers", "2", "--out", str(out), timeout=240)
    assert first.returncode in (0, 1), first.stdout + first.stderr
    rows = _rows(out)
    assert len(rows) == 8
    kept = (out / "results.csv").read_text().splitlines()[:4]  # header and three rows
    (out / "results.csv").write_text("\n".join(kept) + "\n")
    again = fossbot_hil(*SWEEP, "--workers", "2", "--out", str(out), "--resume", timeout=240)
    assert "(3 done already)" in again.stdout, again.stdout + again.stderr
    assert _verdicts(_rows(out)) == _verdicts(rows)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--seeds", "0"], "--seeds"),
        (["--thresholds", "0.3,-1"], "threshold"),
        (["--scenario", "no_such_scenario"], "unknown scenario"),
        (["--faults", "no_such_profile"], "no_such_profile"),
        (["--domain-id", "5"], "--domain-id"),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers"),
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
