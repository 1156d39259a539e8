"""Scores: each scenario's weight, whether students see it, and the points a row earns (pure).

A scenario that passed earns its whole share; one that did not earns nothing,
or, with partial credit, its share times the ticks held of the ticks it
should have run (a scenario that broke early counts its missing ticks as not
held). With no grading file every scenario weighs 1, so the score is the
number of scenarios passed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

__all__ = ["ScenarioScore", "ScorePlan", "held_of"]

PASS = "PASS"


@dataclass(frozen=True)
class ScenarioScore:
    """How one scenario counts, and how students see it."""

    name: str  # the scenario's name: the class table's column
    weight: float = 1.0
    hidden: bool = False  # students see only `label` and whether it passed
    show_failure: bool = False  # hidden only: students also see its first failure
    label: str = ""  # hidden only: what students see instead of the name, e.g. "hidden 1"

    @property
    def shown_name(self) -> str:
        """The name a student's report and the LMS give this scenario."""
        return self.label or self.name if self.hidden else self.name


@dataclass(frozen=True)
class ScorePlan:
    """The scenarios in table order, and how their verdicts become points."""

    scenarios: tuple[ScenarioScore, ...]
    points: float | None = None  # what a full pass earns; None: the sum of the weights
    partial_credit: bool = False

    @classmethod
    def equal(cls, names: Sequence[str]) -> ScorePlan:
        """Every scenario weighs 1, none hidden: the score is the number passed."""
        return cls(tuple(ScenarioScore(n) for n in names))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.scenarios)

    @property
    def hidden(self) -> frozenset[str]:
        return frozenset(s.name for s in self.scenarios if s.hidden)

    def entry(self, name: str) -> ScenarioScore:
        for s in self.scenarios:
            if s.name == name:
                return s
        raise KeyError(name)

    @property
    def max_score(self) -> float:
        weights = sum(s.weight for s in self.scenarios)
        return self.points if self.points is not None else weights

    def max_points(self, name: str) -> float:
        """What `name` is worth: its weight, scaled so the weights add up to `points`."""
        weights = sum(s.weight for s in self.scenarios)
        return self.entry(name).weight * self.max_score / weights if weights else 0.0

    def earned(self, name: str, verdict: str, ticks: tuple[int, int] | None = None) -> float:
        """The points `name` earns with `verdict` and (held, of) ticks."""
        worth = self.max_points(name)
        if verdict == PASS:
            return worth
        if self.partial_credit and ticks and ticks[1] > 0:
            held, of = ticks
            return worth * max(0, min(held, of)) / of
        return 0.0

    def score(
        self, verdicts: Mapping[str, str], ticks: Mapping[str, tuple[int, int]] | None = None
    ) -> float:
        """The row's total, rounded to hundredths."""
        ticks = ticks or {}
        total = sum(
            self.earned(s.name, verdicts.get(s.name, ""), ticks.get(s.name)) for s in self.scenarios
        )
        return round(total, 2)


def held_of(judged: int, failed: int, planned: int) -> tuple[int, int] | None:
    """(ticks held, ticks the scenario has) of a run that judged `judged` ticks, `failed` of
    them failed, of a scenario that has `planned` when nothing breaks: the ticks a run that
    broke early never reached count as not held. None: nothing to count."""
    of = max(judged, planned)
    return (max(0, judged - failed), of) if of > 0 else None


def points_text(value: float) -> str:
    """3 -> '3', 2.5 -> '2.5', 1/3 -> '0.33'."""
    return f"{round(value, 2):g}"
