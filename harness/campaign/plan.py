"""A campaign's runs: every combination of its factors, each with a stable key (pure).

The key names the run by its factor levels, so a resumed campaign knows
which runs are done whatever order they finished in, and two campaigns
over the same levels give the same rows.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import asdict, dataclass

SCENARIO_FAULTS = "scenario"  # the fault level that keeps each scenario's own profile


@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign: a scenario under one fault level, seed and threshold."""

    scenario: str
    faults: str  # a profile list such as "noisy,drop(rate=0.1)", or SCENARIO_FAULTS
    seed: int
    threshold: float | None  # None: the scenario's own

    @property
    def key(self) -> str:
        threshold = "scenario" if self.threshold is None else repr(self.threshold)
        return f"{self.scenario}|{self.faults}|{self.seed}|{threshold}"

    def as_row(self) -> dict[str, object]:
        row = asdict(self)
        row["threshold"] = "" if self.threshold is None else self.threshold
        return {"key": self.key, **row}


def plan(
    scenarios: Sequence[str],
    faults: Sequence[str],
    seeds: Sequence[int],
    thresholds: Sequence[float | None],
) -> list[RunSpec]:
    """Every combination, scenario-major, in the order the levels were given."""
    combos = itertools.product(scenarios, faults, seeds, thresholds)
    return [RunSpec(s, f, seed, t) for s, f, seed, t in combos]
