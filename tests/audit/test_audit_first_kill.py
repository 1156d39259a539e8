"""An audit stops each mutant's scenario at its first failed tick (all a kill needs), runs
the control whole, and balances its batches by the mistakes' measured cost. The batches
are pure; the runs are real mutant nodes on two short scenarios (``run_batch``, the Dask
task's body, without the cluster)."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_audit_unit_errors import by_name, config, outcome_of

from harness.audit.mutants import CONTROL, MUTANTS
from harness.audit.report import audit_json
from harness.audit.suite_audit import audit_units, batches, unit_cost
from harness.audit.task import run_batch

ALL = [m.name for m in MUTANTS]


def entries(result) -> dict[str, dict]:
    return {e["scenario"]: e for run in result.runs for e in run["results"]}


def test_mutants_stop_at_their_first_kill_and_the_control_runs_whole() -> None:
    units = {u.name: u for u in audit_units(ALL)}
    assert not units[CONTROL].stop_at_first_failure
    assert all(units[name].stop_at_first_failure for name in ALL)
    # --repeat: flips are compared on whole runs
    assert not any(u.stop_at_first_failure for u in audit_units(ALL, whole_runs=True))


def test_batches_spread_the_costly_mistakes_and_finish_together() -> None:
    units = audit_units(ALL)
    found = batches(units, 2)
    assert found == batches(units, 2)  # deterministic
    assert sorted(u.name for b in found for u in b) == sorted(u.name for u in units)
    loads = [sum(unit_cost(u) for u in batch) for batch in found]
    assert loads[0] >= loads[1]  # the costliest batch first
    assert loads[0] - loads[1] <= min(unit_cost(u) for u in units)  # as even as it gets
    costliest = sorted(units, key=lambda u: -unit_cost(u))[:2]
    assert {b[0] for b in found} == set(costliest)  # one in each, first in it
    for batch in found:
        costs = [unit_cost(u) for u in batch]
        assert costs == sorted(costs, reverse=True)


@pytest.mark.ros
@pytest.mark.timeout(200)
def test_a_killed_scenario_ends_at_its_first_failed_tick(tmp_path: Path) -> None:
    """The silent mistake's wall run ends at its first unanswered scan, the wrong answer's
    at its first wrong one; the control is judged on every tick and passes; the matrix and
    audit.json kill both."""
    setup = config(tmp_path)
    results = run_batch(tuple(audit_units(["goes_silent", "angle_in_degrees"])), setup, 1)
    found = by_name(results)
    control = entries(found[CONTROL])
    assert {s: e["verdict"] for s, e in control.items()} == {"near_wall": "PASS", "clear": "PASS"}
    assert not any(e["stopped_early"] for e in control.values())
    assert control["near_wall"]["ticks"] == 16  # the whole run
    silent = entries(found["goes_silent"])["near_wall"]
    assert silent["verdict"] == "FAIL" and silent["stopped_early"], silent
    assert 10 <= silent["ticks"] <= 11  # answers 10 scans (the first maybe twice), not the 11th
    assert "no status within the deadline" in silent["first_failure"], silent
    wrong = entries(found["angle_in_degrees"])["near_wall"]
    assert wrong["verdict"] == "FAIL" and wrong["stopped_early"] and wrong["ticks"] < 16, wrong
    outcome = outcome_of(results, setup.scenarios)
    data = audit_json(outcome, repeat=1, seeds=[None])
    killed = {m["name"]: m["killed_by"] for m in data["mutants"]}
    assert killed == {"goes_silent": ["near_wall"], "angle_in_degrees": ["near_wall"]}, data
    assert data["score"]["killed"] == 2 and data["correct_node_failed"] == {}
