"""Audit a suite on a Dask cluster: every mutant and the correct control, one task each.

The same path as ``grade``: units go to the cluster only as workers free up
(``harness.cluster.window``), each runs in a bounded child process, and a
stop flag reaches every running unit on Ctrl-C.
"""

from __future__ import annotations

import contextlib
import uuid
from collections.abc import Callable, Sequence
from typing import Any

from harness.audit.matrix import KillMatrix, kill_matrix
from harness.audit.mutants import CONTROL, mutant_command, mutant_named
from harness.audit.task import AuditConfig, AuditUnit, UnitResult, run_unit

__all__ = ["AuditOutcome", "audit_suite", "audit_units"]

STOP_WAIT_S = 30.0  # on Ctrl-C: for running units to stop their nodes


class AuditOutcome:
    """The matrix, and the correct node's coverage of the suite (its first seed's)."""

    def __init__(self, matrix: KillMatrix, control: UnitResult, units: list[UnitResult]) -> None:
        self.matrix = matrix
        self.control = control
        self.units = units

    @property
    def coverage(self) -> dict[str, Any]:
        runs = self.control.runs
        return dict(runs[0].get("coverage", {})) if runs else {}

    @property
    def coverage_gaps(self) -> list[str]:
        runs = self.control.runs
        return list(runs[0].get("coverage_gaps", [])) if runs else []


def audit_units(names: Sequence[str]) -> list[AuditUnit]:
    """The correct control first (its coverage is wanted early), then the mutants."""
    return [AuditUnit(name, mutant_command(name)) for name in (CONTROL, *names)]


def audit_suite(
    client: Any,
    config: AuditConfig,
    mutants: Sequence[str],
    *,
    on_unit: Callable[[UnitResult, int], None] | None = None,
) -> AuditOutcome:
    """Run the control and `mutants` through the suite on `client`'s cluster; `on_unit`
    gets each unit's result as it comes, with how many units are running then."""
    from harness.cluster.flag import ClusterFlag
    from harness.cluster.window import Window

    units = audit_units(mutants)
    order = sorted(range(len(units)), key=lambda i: (i > 0, not _slow(units[i].name)))
    queued = [units[i] for i in order]  # the control, the slow ones, then the rest
    done: dict[int, UnitResult] = {}
    stop = ClusterFlag()

    def submit(unit: AuditUnit) -> Any:
        key = f"audit-{unit.name}-{uuid.uuid4().hex[:8]}"
        return client.submit(run_unit, unit, config, stop, key=key, pure=False)

    window = Window(client, queued, submit)
    try:
        for index, future in window:
            done[order[index]] = _outcome(future, queued[index])
            if on_unit is not None:
                on_unit(done[order[index]], len(window.running))
    except BaseException:
        with contextlib.suppress(Exception):  # the scheduler may be what went away
            stop.set()
            from distributed import wait as wait_for

            wait_for(list(window.running), timeout=STOP_WAIT_S)
        raise
    results = [done[i] for i in range(len(units))]
    control, mutant_results = results[0], results[1:]
    matrix = kill_matrix(config.scenarios, mutant_results, control)
    return AuditOutcome(matrix, control, mutant_results)


def _slow(name: str) -> bool:
    return name != CONTROL and mutant_named(name).slow


def _outcome(future: Any, unit: AuditUnit) -> UnitResult:
    """The unit's result; one lost to the cluster is a result too (it killed nothing)."""
    try:
        outcome = future.result()
    except Exception as err:  # noqa: BLE001 - lost to the cluster, not to the node
        return UnitResult(unit.name, error=f"lost to the cluster: {type(err).__name__}: {err}")
    assert isinstance(outcome, UnitResult)
    return outcome
