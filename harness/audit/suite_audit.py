"""Audit a suite on a Dask cluster: every mutant and the correct control, in batches.

The same path as ``grade``: batches go to the cluster only as workers free
up (``harness.cluster.window``), each runs in a bounded child process, and a
stop flag reaches every running batch on Ctrl-C.
"""

from __future__ import annotations

import contextlib
import uuid
from collections.abc import Callable, Sequence
from typing import Any

from harness.audit.matrix import KillMatrix, kill_matrix
from harness.audit.mutants import CONTROL, mutant_command, mutant_named
from harness.audit.task import AuditConfig, AuditUnit, UnitResult, run_batch

__all__ = ["AuditOutcome", "audit_suite", "audit_units", "batches", "unit_cost"]

STOP_WAIT_S = 30.0  # on Ctrl-C: for running units to stop their nodes
# One batch per worker thread: one worker process's start-up each, and batches of equal
# measured cost (Mutant.cost_s) finish together.
BATCHES_PER_THREAD = 1
CONTROL_COST_S = 0.37  # a scenario of the correct node's suite, run whole


class AuditOutcome:
    """The matrix, and the correct node's coverage of the suite (its first seed's)."""

    def __init__(self, matrix: KillMatrix, control: UnitResult) -> None:
        self.matrix = matrix
        self.control = control

    @property
    def coverage(self) -> dict[str, Any]:
        runs = self.control.runs
        return dict(runs[0].get("coverage", {})) if runs else {}

    @property
    def coverage_gaps(self) -> list[str]:
        runs = self.control.runs
        return list(runs[0].get("coverage_gaps", [])) if runs else []


def audit_units(names: Sequence[str], *, whole_runs: bool = False) -> list[AuditUnit]:
    """The correct control, then the mutants, each a node command. A mutant's scenario
    ends at its first failed tick (all a kill needs), unless `whole_runs` (--repeat: the
    verdicts that flip are compared on whole runs); the control always runs whole."""
    control = AuditUnit(CONTROL, mutant_command(CONTROL))
    stop = not whole_runs
    return [control, *(AuditUnit(n, mutant_command(n), stop_at_first_failure=stop) for n in names)]


def audit_suite(
    client: Any,
    config: AuditConfig,
    mutants: Sequence[str],
    *,
    on_unit: Callable[[UnitResult, int], None] | None = None,
) -> AuditOutcome:
    """Run the control and `mutants` through the suite on `client`'s cluster, in batches
    (`batches`); `on_unit` gets each unit's result as its batch ends, with how many
    batches are running then."""
    from harness.cluster.flag import ClusterFlag
    from harness.cluster.window import Window, cluster_threads

    units = audit_units(mutants, whole_runs=len(config.seeds) > 1)
    queued = batches(units, BATCHES_PER_THREAD * cluster_threads(client))
    done: dict[str, UnitResult] = {}
    stop = ClusterFlag()

    def submit(index: int) -> Any:
        key = f"audit-batch-{index + 1}-{uuid.uuid4().hex[:8]}"
        return client.submit(run_batch, queued[index], config, index + 1, stop, key=key, pure=False)

    window = Window(client, range(len(queued)), submit)
    try:
        for index, future in window:
            for outcome in _outcomes(future, queued[index]):
                done[outcome.name] = outcome
                if on_unit is not None:
                    on_unit(outcome, len(window.running))
    except BaseException:
        with contextlib.suppress(Exception):  # the scheduler may be what went away
            stop.set()
            from distributed import wait as wait_for

            wait_for(list(window.running), timeout=STOP_WAIT_S)
        raise
    results = [done[unit.name] for unit in units]
    control, mutant_results = results[0], results[1:]
    matrix = kill_matrix(config.scenarios, mutant_results, control)
    return AuditOutcome(matrix, control)


def batches(units: Sequence[AuditUnit], count: int) -> list[tuple[AuditUnit, ...]]:
    """`units` in at most `count` batches of about equal expected cost (`unit_cost`).

    Costliest first, each unit joins the batch with the least cost so far, so
    the mistakes that wait out deadlines spread out and quick ones even them;
    the same units give the same batches. A batch shares one warm worker
    process, so the fewer batches, the less start-up.
    """
    count = max(1, min(count, len(units)))
    loads = [0.0] * count
    chosen: list[list[AuditUnit]] = [[] for _ in range(count)]
    for unit in sorted(units, key=lambda u: -unit_cost(u)):  # stable: control, then order
        lightest = loads.index(min(loads))
        chosen[lightest].append(unit)
        loads[lightest] += unit_cost(unit)
    ranked = sorted(range(count), key=lambda i: -loads[i])
    return [tuple(chosen[i]) for i in ranked if chosen[i]]


def unit_cost(unit: AuditUnit) -> float:
    """Seconds a scenario of the unit's suite is expected to take (the mutant's measured
    cost_s; the control runs whole, and quickly)."""
    if unit.name == CONTROL:
        return CONTROL_COST_S
    return mutant_named(unit.name).cost_s


def _outcomes(future: Any, batch: tuple[AuditUnit, ...]) -> list[UnitResult]:
    """The batch's results; a batch lost to the cluster (its Dask worker died) makes each of
    its units an error saying so: neither a kill nor a survivor."""
    try:
        outcomes = future.result()
    except Exception as err:  # noqa: BLE001 - lost to the cluster, not to the node
        why = f"lost to the cluster: {type(err).__name__}: {err}"
        return [UnitResult(unit.name, error=why) for unit in batch]
    assert isinstance(outcomes, list)
    return outcomes
