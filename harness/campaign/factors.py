"""Which factors a campaign's failures depend on, said in plain words (pure).

``explain`` reads the rows as ``csv.DictReader`` gives them (any value may
be a string) and says, most telling first: failures confined to levels of
one factor (an ordered range for the threshold and the variations), or to
a pair of factors when that says more, or "every level of every factor";
then the totals and each factor's rate per level (docs/campaigns.md).
Seeds carry no meaningful order: "some seeds" or "every seed". A verdict
that is not PASS or FAIL counts as an ERROR, a failure named apart (a run
that does not say it passed did not pass).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from itertools import combinations

from harness.judge.verdicts import RunVerdict

FACTORS = ("scenario", "faults", "threshold", "seed")
UNORDERED = ("scenario", "faults", "seed")  # the others are quantities: "threshold <= 0.2"
Factors = tuple[str, ...]

Level = str | int | float | None
Row = Mapping[str, str | int | float | None]

_MAX_NAMED = 4  # levels named in one phrase before "and N more"
_MAX_FINDINGS = 3  # "fails only ..." lines
_MAX_PAIRS = 2  # of which combinations of two factors
_MAX_RATE_LEVELS = 6  # levels shown in a factor's rate line
_MAX_CELLS = 4  # failing combinations listed by name
_NOUNS = {"scenario": "scenarios", "faults": "faults", "threshold": "thresholds", "seed": "seeds"}


@dataclass(frozen=True)
class _Run:
    """One row, reduced to its factor levels and whether it passed."""

    levels: tuple[Level, ...]  # one per FACTORS, in that order
    verdict: str  # "PASS", "FAIL" or "ERROR"


@dataclass
class _Tally:
    """Runs, FAILs and ERRORs of some set of runs."""

    runs: int = 0
    fail: int = 0
    error: int = 0

    @property
    def failed(self) -> int:
        return self.fail + self.error

    @property
    def rate(self) -> float:
        return self.failed / self.runs if self.runs else 0.0

    def add(self, run: _Run) -> None:
        self.runs += 1
        self.fail += run.verdict == RunVerdict.FAIL
        self.error += run.verdict == RunVerdict.ERROR

    def minus(self, other: _Tally) -> _Tally:
        return _Tally(self.runs - other.runs, self.fail - other.fail, self.error - other.error)

    def __add__(self, other: _Tally) -> _Tally:
        return _Tally(self.runs + other.runs, self.fail + other.fail, self.error + other.error)


@dataclass
class _Finding:
    """A "fails only ..." statement: where, and the runs there."""

    head: str  # what follows "fails only "
    there: _Tally
    rank: tuple[int, ...] = field(default=())  # ties: singles first, then factor order


# --- reading rows -------------------------------------------------------------------------------


def _text(value: object) -> str:
    """A cell as stripped text; None and NaN are empty (csv gives "" for missing)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return str(value).strip()


def _number(value: object) -> float | None:
    """A float-like cell as a float, or None when empty or not a number."""
    if isinstance(value, bool):
        return None
    try:
        number = float(_text(value))
    except ValueError:
        return None
    return None if math.isnan(number) else number


def _level(factor: str, value: object) -> Level:
    """A factor's level, typed so numeric levels sort and compare as numbers."""
    text = _text(value)
    if not text:
        return None
    if factor == "faults":  # "a, b" and "a,b" are the same profile list
        return ",".join(part.strip() for part in text.split(",") if part.strip()) or None
    if factor == "scenario":
        return text
    number = _number(text)  # a threshold, a seed, a varied quantity
    if number is None:
        return text
    if factor == "seed" and number.is_integer():
        return int(number)
    return number


def _verdict(value: object) -> str:
    """PASS, FAIL or ERROR; anything that does not say it passed or failed is an ERROR."""
    verdict = RunVerdict.read(_text(value))
    return RunVerdict.ERROR if verdict is RunVerdict.NOT_RUN else verdict


def _runs(rows: Iterable[Row], factors: Factors) -> list[_Run]:
    """The rows as runs; keys other than the factors and verdict are ignored."""
    return [
        _Run(tuple(_level(f, row.get(f)) for f in factors), _verdict(row.get("verdict")))
        for row in rows
    ]


# --- levels and their names ---------------------------------------------------------------------


def _order(level: Level) -> tuple[int, float, str]:
    """Sort key: missing first, then numbers ascending, then text."""
    if level is None:
        return (0, 0.0, "")
    if isinstance(level, int | float):
        return (1, float(level), "")
    return (2, 0.0, level)


def _label(factor: str, level: Level) -> str:
    """A level as people write it (0.3, not 0.30000000000000004)."""
    if level is None:
        return "(scenario's own)" if factor == "threshold" else "(none)"
    if isinstance(level, float):
        return f"{level:g}"
    text = str(level)
    return f'"{text}"' if "," in text else text


def _join(words: list[str], limit: int = _MAX_NAMED) -> str:
    """'a', 'a or b', 'a, b or c', 'a, b, c, d or 2 more'."""
    if len(words) > limit:
        return f"{', '.join(words[:limit])} or {len(words) - limit} more"
    if len(words) == 1:
        return words[0]
    return f"{', '.join(words[:-1])} or {words[-1]}"


def _failed_phrase(tally: _Tally, where: str = "") -> str:
    """'12 of 20 runs there failed', FAIL and ERROR named apart when there were ERRORs."""
    noun = "run" if tally.runs == 1 else "runs"
    errors = f" ({tally.fail} FAIL, {tally.error} ERROR)" if tally.error else ""
    return f"{tally.failed} of {tally.runs} {noun}{where} failed{errors}"


# --- tallies ------------------------------------------------------------------------------------


def _tally(runs: Iterable[_Run]) -> _Tally:
    total = _Tally()
    for run in runs:
        total.add(run)
    return total


def _by_level(runs: list[_Run], index: int) -> dict[Level, _Tally]:
    """Each level of one factor with its runs' tally, levels in sort order."""
    tallies: dict[Level, _Tally] = {}
    for run in runs:
        tallies.setdefault(run.levels[index], _Tally()).add(run)
    return {level: tallies[level] for level in sorted(tallies, key=_order)}


def _failing(tallies: Mapping[Level, _Tally]) -> list[Level]:
    return [level for level, tally in tallies.items() if tally.failed]


# --- describing a set of levels -----------------------------------------------------------------


def _range(factor: str, tallies: Mapping[Level, _Tally], chosen: list[Level]) -> str | None:
    """'threshold <= 0.2 (...)' when the failing levels of a quantity all lie below (or
    above) every passing one; None when they do not, or a failing level is not a number."""
    if factor in UNORDERED:
        return None
    numbers = [lv for lv in tallies if isinstance(lv, float)]
    if len(chosen) == len(tallies) or any(not isinstance(lv, float) for lv in chosen):
        return None
    k = len(chosen)
    if k >= len(numbers):
        return None
    if numbers[:k] == chosen:
        return f"{factor} <= {chosen[-1]:g} (every run from {numbers[k]:g} up passed)"
    if numbers[-k:] == chosen:
        return f"{factor} >= {chosen[0]:g} (every run up to {numbers[-k - 1]:g} passed)"
    return None


def _describe(factor: str, tallies: Mapping[Level, _Tally], chosen: list[Level]) -> str:
    """Some levels of a factor in words: 'faults drifting_rate', 'threshold <= 0.2 (...)',
    'some seeds (2 of 5: 1 or 4)'."""
    ranged = _range(factor, tallies, chosen)
    if ranged:
        return ranged
    names = _join([_label(factor, lv) for lv in chosen])
    if factor == "seed":
        return f"some seeds ({len(chosen)} of {len(tallies)}: {names})"
    noun = factor if len(chosen) == 1 or factor == "faults" else _NOUNS.get(factor, factor)
    return f"{noun} {names}"


def _short(description: str) -> str:
    """A description without its parenthesis, for use inside a longer phrase."""
    ranged = " <= " in description or " >= " in description
    return description.split(" (", 1)[0] if ranged else description


# --- findings -----------------------------------------------------------------------------------


def _single_findings(runs: list[_Run], varying: list[int], factors: Factors) -> list[_Finding]:
    """Each factor whose failures sit in a strict subset of its levels."""
    found = []
    for index in varying:
        factor = factors[index]
        tallies = _by_level(runs, index)
        chosen = _failing(tallies)
        if len(chosen) == len(tallies):
            continue
        description = _describe(factor, tallies, chosen)
        word = "when" if _range(factor, tallies, chosen) else "with"
        there = _tally(r for r in runs if r.levels[index] in chosen)
        found.append(_Finding(f"{word} {description}", there, (0, index)))
    return found


def _cells_phrase(
    pair: tuple[int, int], cells: list[tuple[Level, Level]], observed: int, factors: Factors
) -> str:
    """'in 2 of 9 combinations of faults and threshold (faults a with threshold 0.1; ...)'."""
    f1, f2 = factors[pair[0]], factors[pair[1]]
    named = [f"{f1} {_label(f1, a)} with {f2} {_label(f2, b)}" for a, b in cells]
    return f"in {len(cells)} of {observed} combinations of {f1} and {f2} ({'; '.join(named)})"


def _pair_finding(runs: list[_Run], pair: tuple[int, int], factors: Factors) -> _Finding | None:
    """Failures confined within two factors: to a block of levels of each
    ('with faults a and threshold <= 0.2'), or to a few named combinations."""
    i, j = pair
    key = lambda run: (run.levels[i], run.levels[j])  # noqa: E731
    cells: dict[tuple[Level, Level], _Tally] = {}
    for run in runs:
        cells.setdefault(key(run), _Tally()).add(run)
    failing = sorted((c for c, t in cells.items() if t.failed), key=lambda c: tuple(map(_order, c)))
    if len(failing) == len(cells):
        return None
    by_i, by_j = _by_level(runs, i), _by_level(runs, j)
    chosen_i, chosen_j = _failing(by_i), _failing(by_j)
    block = [c for c in cells if c[0] in chosen_i and c[1] in chosen_j]
    strict = len(chosen_i) < len(by_i) and len(chosen_j) < len(by_j)
    seeded = factors[j] == "seed"  # seeds are never named one by one
    if len(failing) < len(block) and len(failing) <= _MAX_CELLS and not seeded:
        head = _cells_phrase(pair, failing, len(cells), factors)
        there = _tally(r for r in runs if key(r) in set(failing))
    elif strict:
        first = _short(_describe(factors[i], by_i, chosen_i))
        second = _short(_describe(factors[j], by_j, chosen_j))
        head = f"with {first} and {second}"
        there = _tally(r for r in runs if key(r) in set(block))
    else:
        return None
    return _Finding(head, there, (1, i, j))


def _findings(runs: list[_Run], varying: list[int], factors: Factors) -> list[_Finding]:
    """The 'fails only ...' statements worth saying, most telling first: a pair is
    said only when it narrows the failures down further than every single factor."""
    singles = _single_findings(runs, varying, factors)
    best_single = max((f.there.rate for f in singles), default=0.0)
    pairs = [
        found
        for pair in combinations(varying, 2)
        if (found := _pair_finding(runs, pair, factors)) and found.there.rate > best_single + 1e-12
    ]
    pairs = sorted(pairs, key=_telling)[:_MAX_PAIRS]
    return sorted(singles + pairs, key=_telling)[:_MAX_FINDINGS]


def _telling(finding: _Finding) -> tuple[float, tuple[int, ...]]:
    """Higher failure rate where the failures are confined = more telling."""
    return (-finding.there.rate, finding.rank)


def _finding_line(finding: _Finding, total: _Tally) -> str:
    elsewhere = total.minus(finding.there)
    return (
        f"fails only {finding.head}: {_failed_phrase(finding.there, ' there')}, "
        f"{elsewhere.failed} of {elsewhere.runs} elsewhere"
    )


# --- per-factor rates ---------------------------------------------------------------------------


def _rate(tally: _Tally) -> str:
    errors = f" ({tally.error} ERROR)" if tally.error else ""
    return f"{tally.failed}/{tally.runs}{errors}"


def _factor_line(runs: list[_Run], index: int, factors: Factors) -> str:
    """One factor's failure rate per level; seeds only 'some' or 'every'."""
    factor = factors[index]
    tallies = _by_level(runs, index)
    if factor == "seed":
        chosen = _failing(tallies)
        if len(chosen) == len(tallies):
            return f"seed: failures with every seed ({len(tallies)} seeds)"
        return f"seed: failures with {_describe(factor, tallies, chosen)}"
    shown = list(tallies.items())
    rest = ""
    if len(shown) > _MAX_RATE_LEVELS:
        shown.sort(key=lambda item: -item[1].rate)  # stable: sort order among equals
        others = sum((t for _, t in shown[_MAX_RATE_LEVELS - 1 :]), _Tally())
        rest = f", {len(shown) - _MAX_RATE_LEVELS + 1} more levels {_rate(others)}"
        shown = shown[: _MAX_RATE_LEVELS - 1]
    levels = ", ".join(f"{_label(factor, lv)} {_rate(t)}" for lv, t in shown)
    return f"{factor}, runs failed per level: {levels}{rest}"


# --- the summary --------------------------------------------------------------------------------


def explain(
    rows: Iterable[Mapping[str, str | int | float | None]], varied: Sequence[str] = ()
) -> list[str]:
    """A campaign's summary lines, most telling first; `varied` ordered like the threshold."""
    factors: Factors = (*FACTORS, *varied)
    runs = _runs(rows, factors)
    total = _tally(runs)
    if not runs:
        return ["no runs: nothing to explain"]
    if not total.failed:
        return ["the 1 run passed" if total.runs == 1 else f"all {total.runs} runs passed"]
    varying = [i for i in range(len(factors)) if len({r.levels[i] for r in runs}) > 1]
    totals = _failed_phrase(total)
    if not varying:
        why = "only 1 run" if total.runs == 1 else f"no factor varies across the {total.runs} runs"
        return [f"{totals}; {why}: the failures cannot be tied to a factor"]
    findings = _findings(runs, varying, factors)
    lines = [_finding_line(f, total) for f in findings]
    if not any(f.rank[0] == 0 for f in findings):
        lines.append(
            f"fails at every level of every factor ({total.failed} of {total.runs} runs): "
            "not tied to one factor"
        )
    lines.append(totals)
    lines.extend(_factor_line(runs, i, factors) for i in varying if _useful(runs, i, factors))
    return lines


def _useful(runs: list[_Run], index: int, factors: Factors) -> bool:
    """A rate line says something when the rates differ (seeds: always, for flakiness)."""
    rates = {(t.failed, t.runs) for t in _by_level(runs, index).values()}
    return factors[index] == "seed" or len(rates) > 1
