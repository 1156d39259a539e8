"""Parallel sessions (pytest-xdist): runs never hear each other; a board port is taken in turns.

Cross-talk check: one worker runs the reference node while the other runs a
student's node with an inverted warning, at the same time. If either
worker's harness heard the other's node, the reference runs would fail
(two statuses per scan, wrong Bools) and the student's failures would stop
being exactly "wrong warning". Every run logs its domain and its start and
end; runs that overlapped in time must have used different domains.
"""

from __future__ import annotations

import itertools
import json
import os
import sys
from pathlib import Path

import pytest

from harness.serial_line.port_lock import hold_port

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(120)

STUDENT = Path(__file__).parents[1] / "ros" / "student_node.py"

BARRIER = """
import json, os, time
from pathlib import Path

import pytest

RUNS = Path({runs!r})
SCENARIOS = ("approach_wall", "rotate_beside_wall", "obstacle_at_side")


def one_status_per_scan(result):
    return all(len(r.answers.statuses) == 1 for r in result.records)


@pytest.fixture(scope="session", autouse=True)
def every_worker_started():
    # Hold each worker until both are here, so that their runs overlap.
    me = os.environ["PYTEST_XDIST_WORKER"]
    (RUNS.parent / f"started-{{me}}").touch()
    deadline = time.monotonic() + 60
    while len(list(RUNS.parent.glob("started-*"))) < 2:
        assert time.monotonic() < deadline, "the other worker never started"
        time.sleep(0.02)  # polling a bounded condition


@pytest.fixture
def logged(hil):
    # hil.run, with the run's worker, domain and time span appended to RUNS.
    def run(group, case, **options):
        started = time.time()
        result = hil.run(case, **options)
        entry = dict(
            group=group,
            worker=os.environ["PYTEST_XDIST_WORKER"],
            scenario=result.scenario,
            domain=result.domain_id,
            started=started,
            ended=time.time(),
            ok=result.ok,
        )
        with RUNS.open("a") as log:
            log.write(json.dumps(entry) + "\\n")
        return result

    return run
"""

REFERENCE_TESTS = """
import pytest

from conftest import SCENARIOS, one_status_per_scan


@pytest.mark.hil_scenarios(*SCENARIOS)
def test_reference_node(logged, hil_case):
    result = logged("reference", hil_case)
    assert result.ok, result.explanation
    assert one_status_per_scan(result)
"""

STUDENT_TESTS = """
import pytest

from conftest import SCENARIOS, one_status_per_scan

STUDENT = {student!r}


@pytest.mark.hil_scenarios(*SCENARIOS)
def test_inverted_warning(logged, hil_case):
    result = logged("student", hil_case, node=STUDENT)
    assert not result.ok and result.failed_ticks, result.explanation
    assert one_status_per_scan(result), result.explanation
    failures = {{f for r in result.failed_ticks for f in r.verdict.failures}}
    assert all(f.startswith("expected warning") for f in failures), failures
"""


def overlap(a: dict, b: dict) -> bool:
    return a["started"] < b["ended"] and b["started"] < a["ended"]


@pytest.mark.ros
def test_parallel_workers_run_good_and_buggy_nodes_without_cross_talk(
    pytester: pytest.Pytester,
) -> None:
    runs = pytester.path / "runs.jsonl"
    pytester.makeconftest(BARRIER.format(runs=str(runs)))
    student = f"{sys.executable} {STUDENT} inverted_bool"
    pytester.makepyfile(
        test_reference=REFERENCE_TESTS, test_student=STUDENT_TESTS.format(student=student)
    )
    # loadfile: one file per worker, so the two nodes run at the same time.
    # (loadgroup would say so more directly, but pytest-xdist 3.8 cannot
    # regroup tests under pytest 9.)
    result = pytester.runpytest_subprocess(
        "-n", "2", "--dist", "loadfile", "--hil-timeout", "5", "-p", "no:cacheprovider", timeout=100
    )
    result.assert_outcomes(passed=6)
    log = [json.loads(line) for line in runs.read_text().splitlines()]
    assert len(log) == 6
    workers = {
        group: {e["worker"] for e in log if e["group"] == group}
        for group in ("reference", "student")
    }
    assert len(workers["reference"]) == 1 and workers["reference"] != workers["student"]
    concurrent = [
        (a, b)
        for a, b in itertools.combinations(log, 2)
        if a["worker"] != b["worker"] and overlap(a, b)
    ]
    assert concurrent, "no two runs overlapped: the check proved nothing"
    for a, b in concurrent:
        assert a["domain"] != b["domain"], (a, b)


TURNS = """
import os, time
from pathlib import Path

import pytest

LOG = Path({log!r})


def note(what):
    with LOG.open("a") as log:
        log.write(f"{{what}} {{os.environ['PYTEST_XDIST_WORKER']}}\\n")


@pytest.fixture
def queued():
    note("waiting")


@pytest.mark.hil
@pytest.mark.parametrize("n", [1, 2])
def test_board(queued, hil_board, n):
    note("start")
    # Keep the port until the other worker is waiting for it (bounded).
    deadline = time.monotonic() + 30
    while LOG.read_text().count("waiting") < 2:
        assert time.monotonic() < deadline, "the other worker never asked for the port"
        time.sleep(0.02)  # polling a bounded condition
    note("end")
"""


@pytest.fixture
def tty() -> str:
    """A serial device path (a pty slave) to name with --hil-port."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    yield path
    os.close(master)


def test_workers_take_turns_on_one_board_port(pytester: pytest.Pytester, tty: str) -> None:
    """Two hil tests on two workers, one --hil-port: the second starts after the first ends."""
    log = pytester.path / "turns.log"
    pytester.makepyfile(test_turns=TURNS.format(log=str(log)))
    result = pytester.runpytest_subprocess(
        "-n", "2", f"--hil-port={tty}", "-p", "no:cacheprovider", timeout=100
    )
    result.assert_outcomes(passed=2)
    events = [line.split() for line in log.read_text().splitlines() if "waiting" not in line]
    assert [what for what, _ in events] == ["start", "end", "start", "end"], events
    assert events[0][1] == events[1][1] != events[2][1] == events[3][1], events


def test_a_port_held_too_long_fails_the_test_with_the_holder(
    pytester: pytest.Pytester, tty: str
) -> None:
    """The wait is bounded (--hil-port-wait); the failure names who holds the port."""
    pytester.makepyfile("import pytest\n\ndef test_board(hil_board):\n    pass\n")
    with hold_port(tty, 0.0):
        result = pytester.runpytest_subprocess(
            f"--hil-port={tty}", "--hil-port-wait", "0.3", "-p", "no:cacheprovider", timeout=60
        )
    result.assert_outcomes(errors=1)
    holder = f"--hil-port {tty}: in use by pid {os.getpid()} (*), for * s"
    result.stdout.fnmatch_lines([f"{holder}; waited 0.3 s for it to finish"])
