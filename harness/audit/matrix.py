"""The kill matrix: which scenario catches which mistake, reliably (pure).

A mutant is killed by a scenario when it failed it (FAIL or ERROR) in every
seed's suite; a pair that failed in some seeds and passed in others is a
flip: a verdict that depends on luck, reported, never counted as a kill. A
scenario the correct node does not pass every time kills nothing: its
failures say nothing about the mistakes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

__all__ = ["Flip", "KillMatrix", "kill_matrix"]

FAILED = ("FAIL", "ERROR")


class UnitVerdicts(Protocol):
    """What the matrix reads of a unit's suites (``task.UnitResult``)."""

    name: str
    error: str | None

    def verdicts(self, scenario: str) -> list[str]: ...

    def first_failure(self, scenario: str) -> str: ...


@dataclass(frozen=True)
class Flip:
    """A (mutant, scenario) pair whose verdict changed from seed to seed."""

    mutant: str
    scenario: str
    verdicts: tuple[str, ...]

    def as_dict(self) -> dict[str, Any]:
        return {"mutant": self.mutant, "scenario": self.scenario, "verdicts": list(self.verdicts)}


@dataclass(frozen=True)
class KillMatrix:
    """Mutants x scenarios, with what the correct node did in each scenario."""

    scenarios: tuple[str, ...]
    mutants: tuple[str, ...]
    cells: dict[tuple[str, str], str]  # (mutant, scenario) -> "killed" | "survived" | "flip"
    killed_by: dict[str, tuple[str, ...]]
    why: dict[str, str]  # mutant -> the first failure of the first scenario that killed it
    flips: tuple[Flip, ...]
    unsound: dict[str, str]  # scenario -> how the correct node failed it
    unit_errors: dict[str, str]  # unit -> why it did not finish

    @property
    def survivors(self) -> tuple[str, ...]:
        return tuple(m for m in self.mutants if not self.killed_by[m])

    @property
    def score(self) -> tuple[int, int]:
        """(mutants killed, mutants)."""
        return len(self.mutants) - len(self.survivors), len(self.mutants)


def _cell(verdicts: list[str]) -> str:
    failed = [v in FAILED for v in verdicts]
    if failed and all(failed):
        return "killed"
    return "flip" if any(failed) else "survived"


def kill_matrix(
    scenarios: Sequence[str], units: Sequence[UnitVerdicts], control: UnitVerdicts
) -> KillMatrix:
    """The matrix of `units` (the mutants, in order) over `scenarios`, `control` being the
    correct node's unit."""
    unsound = {}
    for scenario in scenarios:
        verdicts = control.verdicts(scenario)
        if not verdicts or any(v != "PASS" for v in verdicts):
            why = control.first_failure(scenario) or control.error or "not run"
            unsound[scenario] = f"{'/'.join(verdicts) or 'NOT RUN'}: {why}"
    cells: dict[tuple[str, str], str] = {}
    killed_by: dict[str, tuple[str, ...]] = {}
    why: dict[str, str] = {}
    flips: list[Flip] = []
    for unit in units:
        kills = []
        for scenario in scenarios:
            verdicts = unit.verdicts(scenario)
            cell = _cell(verdicts)
            cells[unit.name, scenario] = cell
            if cell == "flip":
                flips.append(Flip(unit.name, scenario, tuple(verdicts)))
            if cell == "killed" and scenario not in unsound:
                kills.append(scenario)
        killed_by[unit.name] = tuple(kills)
        if kills:
            why[unit.name] = unit.first_failure(kills[0])
    errors = {u.name: u.error for u in (*units, control) if u.error}
    return KillMatrix(
        tuple(scenarios),
        tuple(u.name for u in units),
        cells,
        killed_by,
        why,
        tuple(flips),
        unsound,
        errors,
    )
