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

__all__ = ["AuditOutcome", "audit_suite", "audit_units", "batches"]

STOP_WAIT_S = 30.0  # on Ctrl-C: for running units to stop their nodes
BATCHES_PER_THREAD = 2  # batches per worker thread: start-up shared, the load still even
SLOW_COST = 6.0  # a mistake that waits out deadlines costs about six quick ones


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


def audit_units(names: Sequence[str]) -> list[AuditUnit]:
    """The correct control, then the mutants, each a node command."""
    return [AuditUnit(name, mutant_command(name)) for name in (CONTROL, *names)]


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

    units = audit_units(mutants)
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
    """`units` in at most `count` batches of about equal cost, the costliest first: a
    mistake whose runs wait out deadlines costs several quick ones. One batch shares one
    worker process and its warm Python, so the fewer batches, the less start-up; enough
    of them keep every worker busy to the end."""
    count = max(1, min(count, len(units)))
    loads = [0.0] * count
    chosen: list[list[AuditUnit]] = [[] for _ in range(count)]
    for unit in sorted(units, key=lambda u: -_cost(u.name)):  # stable: control, then order
        lightest = loads.index(min(loads))
        chosen[lightest].append(unit)
        loads[lightest] += _cost(unit.name)
    ranked = sorted(range(count), key=lambda i: -loads[i])
    return [tuple(chosen[i]) for i in ranked if chosen[i]]


def _cost(name: str) -> float:
    """How long a unit's runs take, relative to a quick one's."""
    if name == CONTROL:
        return 1.0
    return SLOW_COST if mutant_named(name).slow else 1.0


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
