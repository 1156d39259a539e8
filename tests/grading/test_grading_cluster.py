"""`fossbot-hil grade` on real Dask clusters: the embedded default, and one started with
Dask's own `dask scheduler` / `dask worker` commands with a worker killed (-9) mid-class.

The class: a correct student, one reporting the angle in degrees, one whose node
hangs (never comes up, ignores SIGTERM) and one whose node kills the Dask
worker grading it, on a short wall approach. Every student must get exactly one
row, the same through either cluster.
"""

from __future__ import annotations

import contextlib
import csv
import os
import signal
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from cluster_nodes import HANGS, KILLS_ITS_WORKER, variant_source
from command_line import COMMAND
from dask_cluster import GRADING_ENV, children, dask_cluster
from short_scenarios import NEAR_WALL

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]

# A generous per-scan deadline: a busy machine must not turn into a late answer.
GRADE = ["grade", "--ready-timeout", "4", "--timeout", "5"]
GRADE += ["--no-audit"]  # the audit of these scenarios has tests of its own
# Unsandboxed: a node that kills its Dask worker (or writes its pid for the test) must be
# able to; in the sandbox it sees neither (test_grading_sandbox.py grades through both
# clusters sandboxed).
GRADE += ["--no-sandbox"]
STUDENTS = {
    "ana": variant_source("correct"),
    "ben": variant_source("angle_in_degrees"),
    "dan": HANGS,
    "eve": KILLS_ITS_WORKER,
}


@pytest.fixture(scope="module")
def classroom(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """The class's folder and the scenario: grade's arguments."""
    folder = tmp_path_factory.mktemp("class")
    for name, source in STUDENTS.items():
        (folder / name).mkdir()
        (folder / name / "lidar_node.py").write_text(source)
    scenario = tmp_path_factory.mktemp("scenario") / "near_wall.yaml"
    scenario.write_text(NEAR_WALL)
    return [str(folder), "--scenario", str(scenario)]


def _rows(out: Path) -> dict[str, dict[str, str]]:
    with open(out / "grades.csv", encoding="utf-8", newline="") as handle:
        return {row["student"]: row for row in csv.DictReader(handle)}


def _check_class(rows: dict[str, dict[str, str]], output: str) -> None:
    assert sorted(rows) == sorted(STUDENTS), output
    verdicts = {name: row["near_wall"] for name, row in rows.items()}
    assert verdicts == {"ana": "PASS", "ben": "FAIL", "dan": "ERROR", "eve": "NOT RUN"}, output
    assert "degrees" in rows["ben"]["first_failure"], rows["ben"]
    assert rows["dan"]["first_failure"].startswith("node did not start"), rows["dan"]
    assert "the worker grading this student died 2 times" in rows["eve"]["first_failure"]


@pytest.fixture(scope="module")
def embedded(classroom: list[str], tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    """The class graded by the default: an embedded cluster, one worker per core."""
    out = tmp_path_factory.mktemp("embedded") / "grades"
    done = subprocess.run(
        [*COMMAND, *GRADE, *classroom, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "on an embedded Dask cluster of" in done.stdout
    assert "Dask dashboard: http" in done.stdout
    rows = _rows(out)
    _check_class(rows, done.stdout + done.stderr)
    return rows


@pytest.fixture(scope="module")
def external() -> Iterator[tuple[str, list[subprocess.Popen[bytes]]]]:
    """A lab's cluster, as docs/grading.md advises it, with nannies (a killed worker comes
    back): the address and the nanny processes. Its tests share it, as a lab's would."""
    with dask_cluster(2, nanny=True, env=GRADING_ENV) as cluster:
        yield cluster


def test_the_embedded_cluster_grades_every_kind_of_student(embedded: dict[str, dict]) -> None:
    assert embedded["ana"]["passed"] == "1/1"


def test_an_external_cluster_gives_the_same_rows_with_a_worker_killed(
    classroom: list[str],
    embedded: dict[str, dict],
    external: tuple[str, list[subprocess.Popen[bytes]]],
    tmp_path: Path,
) -> None:
    out = tmp_path / "grades"
    address, nannies = external
    grade = subprocess.Popen(
        [*COMMAND, *GRADE, *classroom, "--scheduler", address, "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    assert grade.stdout is not None
    killed = None
    for line in grade.stdout:  # ends when the command does
        if killed is None and ": script, " in line:  # a first student is done
            workers = children(nannies[0].pid)
            if workers:
                killed = workers[0]
                os.kill(killed, signal.SIGKILL)
    grade.wait(timeout=60)
    assert killed is not None, "no worker was killed"
    assert grade.returncode == 0
    rows = _rows(out)
    _check_class(rows, str(rows))
    assert rows == embedded


def test_ctrl_c_stops_the_students_running_on_an_external_cluster(
    external: tuple[str, list[subprocess.Popen[bytes]]], tmp_path: Path
) -> None:
    """Dask cannot interrupt a running task: the grader's stop flag must reach the worker,
    which stops the student's suite and node, while the cluster itself lives on."""
    pid_file = tmp_path / "node.pid"
    (tmp_path / "class" / "gus").mkdir(parents=True)
    (tmp_path / "class" / "gus" / "lidar_node.py").write_text(
        f"import os\nopen({str(pid_file)!r}, 'w').write(str(os.getpid()))\n{HANGS}"
    )
    address, nannies = external
    grade = subprocess.Popen(
        [*COMMAND, "grade", str(tmp_path / "class"), "--scheduler", address]
        + ["--scenario", "approach_wall", "--ready-timeout", "120", "--no-audit"]
        + ["--no-sandbox"]  # the node writes its pid where the test reads it
        + ["--out", str(tmp_path / "grades")],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    deadline = time.monotonic() + 60
    while not pid_file.exists() or not pid_file.read_text():
        assert time.monotonic() < deadline and grade.poll() is None, "the node never started"
        time.sleep(0.05)
    node = int(pid_file.read_text())
    grade.send_signal(signal.SIGINT)
    output, _ = grade.communicate(timeout=60)
    assert grade.returncode == 130, output
    deadline = time.monotonic() + 30
    while Path(f"/proc/{node}").exists() and _state(node) != "Z":
        assert time.monotonic() < deadline, f"the student's node {node} is still running"
        time.sleep(0.05)
    assert all(n.poll() is None for n in nannies), "the cluster must live on"


def _state(pid: int) -> str:
    with contextlib.suppress(OSError):
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    return "gone"
