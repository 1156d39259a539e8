"""Each audit unit's failure is its own: a batch of real mutant nodes in a real worker
process (``run_batch``, the Dask task's body, called here without the cluster), one of them
a node that cannot run, and what the matrix, audit.json, the exit code and grade's warning
make of it. Short scenarios, few units: each batch takes seconds."""

from __future__ import annotations

import io
import json
import shlex
import sys
from pathlib import Path

import pytest
from rich.console import Console
from short_scenarios import NEAR_WALL, nothing_in_range

from harness.audit.known import audit_warning
from harness.audit.matrix import kill_matrix
from harness.audit.mutants import CONTROL, mutant_command
from harness.audit.report import audit_json, exit_code, print_audit
from harness.audit.suite_audit import AuditOutcome
from harness.audit.task import AuditConfig, AuditUnit, UnitResult, run_batch
from harness.grading.class_table import StudentGrade, class_html
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

pytestmark = [pytest.mark.ros, pytest.mark.timeout(200)]

# A node that cannot run, as a student's Python without ROS 2 cannot: the suite makes it a
# usage error (ConfigError), which used to end the worker and every unit after it.
NO_RCLPY = shlex.join(
    [sys.executable, "-c", "raise ModuleNotFoundError(\"No module named 'rclpy'\")"]
)
# A node that kills the audit's worker process (the one running harness.audit.worker).
KILLS_ITS_WORKER = shlex.join(
    [
        sys.executable,
        "-c",
        "import os\n"
        "pid = os.getppid()\n"
        "while pid > 1:\n"
        "    if b'harness.audit.worker' in open(f'/proc/{pid}/cmdline', 'rb').read():\n"
        "        os.kill(pid, 9)\n"
        "    pid = int(open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()[1])\n",
    ]
)


def clear() -> str:
    """Nothing in range for 4 ticks (a silent node waits out each one's deadline)."""
    text = nothing_in_range()
    assert "turn: 1.0" in text
    return text.replace("turn: 1.0", "turn: 0.4")


def config(tmp_path: Path, *, seconds_per_scenario: float = 90.0) -> AuditConfig:
    """Two short scenarios: a wall driven at (16 ticks), and nothing in range."""
    files = {"near_wall": NEAR_WALL, "clear": clear()}
    for name, text in files.items():
        (tmp_path / f"{name}.yaml").write_text(text)
    return AuditConfig(
        scenarios=tuple(files),
        scenario_refs=tuple(str(tmp_path / f"{name}.yaml") for name in files),
        link="ros2",
        options=LinkOptions(),
        settings=RunSettings(),
        seeds=(None,),
        units_dir=tmp_path / "mistakes",
        seconds_per_scenario=seconds_per_scenario,
    )


def mutants(*names: str) -> list[AuditUnit]:
    return [AuditUnit(name, mutant_command(name)) for name in names]


def by_name(results: list[UnitResult]) -> dict[str, UnitResult]:
    return {result.name: result for result in results}


def verdicts(result: UnitResult) -> dict[str, str]:
    return {e["scenario"]: e["verdict"] for run in result.runs for e in run["results"]}


def outcome_of(results: list[UnitResult], scenarios: tuple[str, ...]) -> AuditOutcome:
    found = by_name(results)
    control = found.pop(CONTROL)
    return AuditOutcome(kill_matrix(scenarios, list(found.values()), control), control)


def test_a_mistake_that_cannot_run_keeps_the_others_verdicts(tmp_path: Path) -> None:
    """The unit that cannot run first in its batch: it alone errors, with its reason; the
    correct control after it passes and the mistakes after it are killed."""
    setup = config(tmp_path)
    batch = (AuditUnit("centimetres", NO_RCLPY), *mutants(CONTROL, "angle_in_degrees"))
    found = by_name(run_batch(batch, setup, 1))
    assert "cannot import rclpy" in (found["centimetres"].error or ""), found["centimetres"]
    assert found[CONTROL].error is None and found["angle_in_degrees"].error is None
    assert verdicts(found[CONTROL]) == {"near_wall": "PASS", "clear": "PASS"}
    assert verdicts(found["angle_in_degrees"])["near_wall"] == "FAIL"


def test_an_errored_unit_is_marked_in_the_matrix_the_json_and_the_exit_code(
    tmp_path: Path,
) -> None:
    """The unit that errored is neither a survivor nor a kill: ! in its row, ERROR in its
    count, its reason in audit.json, a score of what ran, exit 1; grade's warning says the
    audit could not run it, and never that it passes."""
    setup = config(tmp_path)
    batch = (*mutants(CONTROL, "warning_latched"), AuditUnit("centimetres", NO_RCLPY))
    outcome = outcome_of(run_batch(batch, setup, 1), setup.scenarios)
    matrix = outcome.matrix
    assert matrix.errors == ("centimetres",) and matrix.survivors == ("warning_latched",)
    assert matrix.score == (0, 1)
    assert exit_code(matrix) == 1
    data = audit_json(outcome, repeat=1, seeds=[None])
    row = next(m for m in data["mutants"] if m["name"] == "centimetres")
    assert row["status"] == "error" and row["killed_by"] == []
    assert "cannot import rclpy" in row["error"]
    assert data["survivors"] == ["warning_latched"] and data["errors"] == ["centimetres"]
    assert data["score"] == {"killed": 0, "judged": 1, "errors": 1, "mutants": 2}
    json.dumps(data)  # audit.json is strict JSON
    out = io.StringIO()
    print_audit(Console(file=out, width=120), outcome)
    text = out.getvalue()
    line = next(x for x in text.splitlines() if x.startswith("centimetres"))
    assert line.split()[1:] == ["!", "!", "ERROR"], text
    assert "score: the suite catches 0 of the 1 mistakes that ran (1 could not run)" in text
    warning = audit_warning(data, "near_wall clear")
    assert warning is not None
    assert warning.startswith("warning: the audit could not run: centimetres: "), warning
    assert "cannot import rclpy" in warning
    assert "of the 1 typical mistakes that ran, these scenarios let 1 pass: warning_latched" in (
        warning
    )
    page = class_html(
        [StudentGrade("ana", "script", {"near_wall": "PASS"})], ["near_wall"], audit=warning
    )
    assert "the audit could not run: centimetres: " in page.decode()


def test_an_audit_whose_control_could_not_run_claims_no_pass(tmp_path: Path) -> None:
    """The correct node is the unit that cannot run: nothing is judged, no mistake is said
    to pass, and grade's warning says the audit could not run, and why."""
    setup = config(tmp_path)
    batch = (AuditUnit(CONTROL, NO_RCLPY), *mutants("angle_in_degrees"))
    outcome = outcome_of(run_batch(batch, setup, 1), setup.scenarios)
    data = audit_json(outcome, repeat=1, seeds=[None])
    assert data["survivors"] == [] and data["errors"] == ["angle_in_degrees"]
    assert exit_code(outcome.matrix) == 1
    warning = audit_warning(data, "near_wall clear") or ""
    assert warning.startswith("warning: the audit could not run: the correct node: "), warning
    assert "angle_in_degrees: failed only where the correct node could not run" in warning
    assert " pass" not in warning and "catch" not in warning, warning


def test_a_unit_past_its_bound_is_stopped_and_the_next_ones_run(tmp_path: Path) -> None:
    """A unit's bound counts from its own start: the slow callback (1.5 s a scan) past its
    3 s is stopped with that reason, and the control and a mistake after it still run."""
    setup = config(tmp_path, seconds_per_scenario=1.5)
    found = by_name(
        run_batch(tuple(mutants("slow_callback", CONTROL, "angle_in_degrees")), setup, 1)
    )
    assert "stopped after 3 s" in (found["slow_callback"].error or ""), found["slow_callback"]
    assert verdicts(found[CONTROL]) == {"near_wall": "PASS", "clear": "PASS"}
    assert verdicts(found["angle_in_degrees"])["near_wall"] == "FAIL"


def test_a_node_that_kills_its_worker_takes_only_its_own_unit(tmp_path: Path) -> None:
    """The worker process dies under the second unit: that unit errors, naming the worker's
    end; the first keeps its verdicts and the last runs in a fresh worker."""
    setup = config(tmp_path)
    batch = (
        *mutants(CONTROL),
        AuditUnit("centimetres", KILLS_ITS_WORKER),
        *mutants("angle_in_degrees"),
    )
    found = by_name(run_batch(batch, setup, 1))
    assert "its worker ended (exit code -9)" in (found["centimetres"].error or ""), found
    assert verdicts(found[CONTROL]) == {"near_wall": "PASS", "clear": "PASS"}
    assert found["angle_in_degrees"].error is None
    assert verdicts(found["angle_in_degrees"])["near_wall"] == "FAIL"


@pytest.mark.slow
@pytest.mark.timeout(400)
def test_the_slow_and_silent_mistakes_first_in_a_batch_leave_every_kill(tmp_path: Path) -> None:
    """The mistakes that wait out deadlines go first in a batch (as ``batches`` orders them):
    each is killed, and so is every quick one after them, the control passing."""
    setup = config(tmp_path)
    slow = ("slow_callback", "goes_silent", "silent_when_clear", "status_only_on_change")
    quick = ("angle_in_degrees", "warning_never", "crash_when_nothing_in_range")
    results = run_batch(tuple(mutants(*slow, CONTROL, *quick)), setup, 1)
    outcome = outcome_of(results, setup.scenarios)
    matrix = outcome.matrix
    assert matrix.unit_errors == {} and matrix.unsound == {}, (matrix.unit_errors, matrix.unsound)
    assert matrix.survivors == (), {r.name: verdicts(r) for r in results}
    assert matrix.score == (len(slow) + len(quick), len(slow) + len(quick))
