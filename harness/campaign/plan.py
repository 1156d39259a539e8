"""A campaign's runs: every combination of its factors, each with a stable key (pure).

The key names the run by its factor levels, so a resumed campaign knows
which runs are done whatever order they finished in, and two campaigns
over the same levels give the same rows.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass

SCENARIO_FAULTS = "scenario"  # the fault level that keeps each scenario's own profile

Variation = tuple[tuple[str, float], ...]  # (name, level) of each generated variation


@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign: a scenario (perhaps varied), one fault level, seed and threshold."""

    scenario: str
    faults: str  # a profile list such as "noisy,drop(rate=0.1)", or SCENARIO_FAULTS
    seed: int
    threshold: float | None  # None: the scenario's own
    variation: Variation = ()  # e.g. (("wall_distance", 1.0), ("speed", 0.5))

    @property
    def key(self) -> str:
        threshold = "scenario" if self.threshold is None else repr(self.threshold)
        key = f"{self.scenario}|{self.faults}|{self.seed}|{threshold}"
        if self.variation:  # absent otherwise: keys of campaigns without variations stay
            key += "|" + ";".join(f"{name}={level!r}" for name, level in self.variation)
        return key

    def as_row(self) -> dict[str, object]:
        row = asdict(self)
        del row["variation"]
        row["threshold"] = "" if self.threshold is None else self.threshold
        return {"key": self.key, **row, **dict(self.variation)}


def plan(
    scenarios: Sequence[str],
    faults: Sequence[str],
    seeds: Sequence[int],
    thresholds: Sequence[float | None],
    variations: Sequence[Variation] = ((),),
) -> list[RunSpec]:
    """Every combination, scenario-major, in the order the levels were given."""
    combos = itertools.product(scenarios, variations, faults, seeds, thresholds)
    return [RunSpec(s, f, seed, t, v) for s, v, f, seed, t in combos]


def variation_levels(levels: Mapping[str, Sequence[float]]) -> list[Variation]:
    """Every combination of the variations' levels (one empty variation when none)."""
    names = list(levels)
    return [tuple(zip(names, combo, strict=True)) for combo in itertools.product(*levels.values())]
