"""The kill matrix: which scenario catches which mistake, reliably (pure).

A kill is a failure (FAIL or ERROR) in every seed's suite; a pair that
fails only in some seeds is a flip, reported, never a kill; a scenario the
correct node does not always pass kills nothing. What could not run is
neither kill nor pass: such a mutant is an error, with why, no survivor,
and the score counts only the mutants judged (docs/audit.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from harness.judge.verdicts import RunVerdict

__all__ = ["CONTROL_NOT_RUN", "Flip", "KillMatrix", "kill_matrix"]

FAILED = (RunVerdict.FAIL, RunVerdict.ERROR)
NOT_RUN = RunVerdict.NOT_RUN
# why a mutant that failed only where the correct node could not run is not judged
CONTROL_NOT_RUN = "the correct node could not run it"


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
    # (mutant, scenario) -> "killed" | "survived" | "flip" | "not run"
    cells: dict[tuple[str, str], str]
    killed_by: dict[str, tuple[str, ...]]  # () for a survivor and for an error
    why: dict[str, str]  # mutant -> the first failure of the first scenario that killed it
    flips: tuple[Flip, ...]
    unsound: dict[str, str]  # scenario -> how the correct node failed it (or did not run it)
    unjudged: frozenset[str]  # of those, the scenarios the correct node could not run
    unit_errors: dict[str, str]  # unit (mutant or "correct") -> why its verdict is unknown

    def status(self, mutant: str) -> str:
        """killed, survived or error (it could not be judged: `unit_errors` says why)."""
        if mutant in self.unit_errors:
            return "error"
        return "killed" if self.killed_by[mutant] else "survived"

    @property
    def survivors(self) -> tuple[str, ...]:
        return tuple(m for m in self.mutants if self.status(m) == "survived")

    @property
    def errors(self) -> tuple[str, ...]:
        """The mutants that could not be judged, in order."""
        return tuple(m for m in self.mutants if self.status(m) == "error")

    @property
    def score(self) -> tuple[int, int]:
        """(mutants killed, mutants judged): what could not run is not counted."""
        killed = sum(1 for m in self.mutants if self.status(m) == "killed")
        return killed, len(self.mutants) - len(self.errors)


def _cell(verdicts: list[str]) -> str:
    if not verdicts or NOT_RUN in verdicts:
        return "not run"
    failed = [v in FAILED for v in verdicts]
    if all(failed):
        return "killed"
    return "flip" if any(failed) else "survived"


def _control_failures(
    scenarios: Sequence[str], control: UnitVerdicts
) -> tuple[dict[str, str], set[str]]:
    """The scenarios the correct node did not pass every time (-> how), and of those the
    ones it could not run (an ERROR, a NOT RUN, or no verdict: nothing was judged)."""
    unsound: dict[str, str] = {}
    unjudged: set[str] = set()
    for scenario in scenarios:
        verdicts = control.verdicts(scenario)
        if verdicts and all(v == RunVerdict.PASS for v in verdicts):
            continue
        why = control.first_failure(scenario) or control.error or "not run"
        unsound[scenario] = f"{'/'.join(verdicts) or NOT_RUN.value}: {why}"
        if not verdicts or any(v in (RunVerdict.ERROR, NOT_RUN) for v in verdicts):
            unjudged.add(scenario)
    return unsound, unjudged


def _unknown(unit: UnitVerdicts, cells: dict[str, str], unjudged: set[str]) -> str | None:
    """Why `unit` (killed by no sound scenario) cannot be called a survivor, or None."""
    if unit.error:
        return unit.error
    for scenario, cell in cells.items():
        if cell == "not run":
            why = unit.first_failure(scenario) or "not run"
            return why if why.startswith(f"{scenario}:") else f"{scenario}: {why}"
    for scenario, cell in cells.items():
        if cell == "killed" and scenario in unjudged:
            return f"{scenario}: {CONTROL_NOT_RUN}"
    return None


def kill_matrix(
    scenarios: Sequence[str], units: Sequence[UnitVerdicts], control: UnitVerdicts
) -> KillMatrix:
    """The matrix of `units` (mutants, in order) over `scenarios`; `control`: the correct node."""
    unsound, unjudged = _control_failures(scenarios, control)
    cells: dict[tuple[str, str], str] = {}
    killed_by: dict[str, tuple[str, ...]] = {}
    why: dict[str, str] = {}
    flips: list[Flip] = []
    errors: dict[str, str] = {}
    for unit in units:
        row = {}
        for scenario in scenarios:
            verdicts = unit.verdicts(scenario)
            row[scenario] = cells[unit.name, scenario] = _cell(verdicts)
            if row[scenario] == "flip":
                flips.append(Flip(unit.name, scenario, tuple(verdicts)))
        kills = tuple(s for s in scenarios if row[s] == "killed" and s not in unsound)
        unknown = _unknown(unit, row, unjudged) if unit.error or not kills else None
        if unknown is not None:
            errors[unit.name] = unknown
            kills = ()
        killed_by[unit.name] = kills
        if kills:
            why[unit.name] = unit.first_failure(kills[0])
    if control.error:
        errors[control.name] = control.error
    return KillMatrix(
        tuple(scenarios),
        tuple(u.name for u in units),
        cells,
        killed_by,
        why,
        tuple(flips),
        unsound,
        frozenset(unjudged),
        errors,
    )
