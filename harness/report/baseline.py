"""Verdicts compared with an earlier run's summary.json (`fossbot-hil run --baseline`), pure.

A node improved step by step fails some scenarios for weeks; CI should
still catch the day a scenario that passed starts failing. Each scenario is
matched with the baseline's of the same scenario and fault profile and
given one of ``KINDS`` (docs/ci.md); one judged differently there (another
threshold, seed or link) is ``not compared``: its verdict then says nothing
about now. `--fail-on regression` fails a run only for a failure not known.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from harness import __version__
from harness.errors import OptionError
from harness.judge.verdicts import RunVerdict

__all__ = [
    "KINDS", "Baseline", "Change", "Comparison", "compare", "load_baseline", "with_comparison",
]  # fmt: skip

SUMMARY = "summary.json"
VERDICTS = tuple(v.value for v in RunVerdict)
#: The order the terminal and the page list them in.
KINDS = ("regressed", "fixed", "still failing", "new", "not compared", "missing", "still passing")
JUDGED_ALIKE = ("link", "threshold", "seed")  # what must match for two verdicts to compare
WARNING_RULE = "warning_when_clear"  # must match too; absent (older summaries): "optional"
_FIELDS: dict[str, type | tuple[type, ...]] = {
    "scenario": str, "verdict": str, "ok": bool, "faults": str, "link": str,
    "threshold": (int, float, str), "seed": int,
}  # fmt: skip
Key = tuple[str, str, int]  # scenario, fault profile, occurrence (a run may repeat a scenario)


@dataclass(frozen=True)
class Baseline:
    """An earlier run's summary.json, checked: its harness version and scenario entries."""

    path: str
    harness: str
    entries: tuple[Mapping[str, Any], ...]


def _bad(text: str) -> OptionError:
    return OptionError.saying("baseline", text)  # "--baseline " in the CLI


def load_baseline(path: str) -> Baseline:
    """Read and check `path` (a summary.json, or the report folder holding one): a
    ConfigError naming the file when it is missing or not one `run --out` writes."""
    file = Path(path)
    folder = file.is_dir()
    if folder:
        file = file / SUMMARY
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        missing = f"a folder without {SUMMARY}" if folder else "no such file"
        raise _bad(f"{path}: {missing}") from None
    except (OSError, UnicodeDecodeError) as err:
        reason = getattr(err, "strerror", None) or str(err).splitlines()[0]
        raise _bad(f"{path}: cannot read it: {reason}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise _bad(f"{path}: not JSON ({err.msg}, line {err.lineno})") from None
    except (ValueError, RecursionError) as err:  # a number too long, nesting too deep
        reason = str(err).split(":")[0].splitlines()[0]
        raise _bad(f"{path}: not JSON this harness reads ({reason})") from None
    entries = _checked(data, path)
    harness = data.get("harness", "unknown")
    if not isinstance(harness, str):
        raise _bad(f"{path}: not a fossbot-hil summary.json (harness is malformed)")
    return Baseline(path=path, harness=harness, entries=entries)


def _checked(data: object, path: str) -> tuple[Mapping[str, Any], ...]:
    """The scenario entries of a summary.json, each with the fields a comparison reads."""
    what = f"{path}: not a fossbot-hil summary.json"
    if not isinstance(data, dict) or not isinstance(data.get("scenarios"), list):
        raise _bad(f"{what} (no list of scenarios)")
    for i, entry in enumerate(data["scenarios"]):
        if not isinstance(entry, dict):
            raise _bad(f"{what} (scenarios[{i}] is not an object)")
        for name, kind in _FIELDS.items():
            value = entry.get(name)
            if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
                raise _bad(f"{what} (scenarios[{i}].{name} is missing or malformed)")
        if entry["verdict"] not in VERDICTS:
            raise _bad(f"{what} (scenarios[{i}].verdict {entry['verdict']!r} is unknown)")
    return tuple(data["scenarios"])


@dataclass(frozen=True)
class Change:
    """One scenario and fault profile, then and now (None: not run that time)."""

    kind: str  # one of KINDS
    scenario: str
    faults: str
    then: str | None  # the verdict in the baseline
    now: str | None  # the verdict of this run
    reason: str = ""  # why it was not compared

    @property
    def fails_now(self) -> bool:
        return self.now is not None and self.now != RunVerdict.PASS

    def as_json(self) -> dict[str, Any]:
        return {
            "change": self.kind,
            "scenario": self.scenario,
            "faults": self.faults,
            "then": self.then,
            "now": self.now,
            "reason": self.reason or None,
        }


@dataclass(frozen=True)
class Comparison:
    """This run against a baseline: one Change per scenario of this run, in run
    order, then one per baseline scenario not run now; `notes` name whatever
    makes the baseline differ as a whole (harness version, scenario set)."""

    baseline: str
    harness: str
    notes: tuple[str, ...]
    changes: tuple[Change, ...]

    @property
    def counts(self) -> dict[str, int]:
        tally = Counter(c.kind for c in self.changes)
        return {kind: tally[kind] for kind in KINDS}

    @property
    def unknown_failures(self) -> list[Change]:
        """What `--fail-on regression` fails for: regressions, and failures with no
        comparable verdict in the baseline (new, or judged differently there)."""
        unknown = ("regressed", "new", "not compared")
        return [c for c in self.changes if c.kind in unknown and c.fails_now]

    @property
    def ok(self) -> bool:
        """Nothing regressed and every failure is a known one."""
        return not self.unknown_failures

    def headline(self) -> str:
        counts = self.counts
        shown = [f"{counts[k]} {k}" for k in KINDS if counts[k] or k in ("regressed", "fixed")]
        return ", ".join(shown)

    def as_json(self) -> dict[str, Any]:
        """summary.json's `baseline` object (docs/reports.md)."""
        return {
            "file": self.baseline,
            "harness": self.harness,
            "notes": list(self.notes),
            "ok": self.ok,
            "counts": {k.replace(" ", "_"): n for k, n in self.counts.items()},
            "changes": [c.as_json() for c in self.changes],
        }


def _keyed(entries: Sequence[Mapping[str, Any]]) -> dict[Key, Mapping[str, Any]]:
    """Entries by scenario, fault profile and how often that pair came before."""
    seen: Counter[tuple[str, str]] = Counter()
    keyed = {}
    for entry in entries:
        pair = (entry["scenario"], entry["faults"])
        keyed[(*pair, seen[pair])] = entry
        seen[pair] += 1
    return keyed


def _same(field: str, then: Any, now: Any) -> bool:
    if field == "threshold":
        try:
            return math.isclose(float(then), float(now), rel_tol=1e-9, abs_tol=1e-12)
        except (TypeError, ValueError):
            return then == now
    return then == now


def _judged_otherwise(then: Mapping[str, Any], now: Mapping[str, Any]) -> str:
    """'' when both verdicts were judged alike, else what differed, in words."""
    differ = [
        f"{field} {then[field]} in the baseline, {now[field]} now"
        for field in JUDGED_ALIKE
        if not _same(field, then[field], now[field])
    ]
    rule_then, rule_now = (e.get(WARNING_RULE, "optional") for e in (then, now))
    if rule_then != rule_now:  # a summary older than the rule judged it "optional"
        differ.append(f"{WARNING_RULE} {rule_then} in the baseline, {rule_now} now")
    return "; ".join(differ)


def _kind(then_ok: bool, now_ok: bool) -> str:
    if then_ok:
        return "still passing" if now_ok else "regressed"
    return "fixed" if now_ok else "still failing"


def _label(key: Key) -> str:
    scenario, faults, n = key
    return f"{scenario} [{faults}]" + (f" #{n + 1}" if n else "")


def compare(baseline: Baseline, entries: Sequence[Mapping[str, Any]]) -> Comparison:
    """This run's summary entries (harness.report.summary.scenario_entry) against `baseline`."""
    before, after = _keyed(baseline.entries), _keyed(entries)
    changes = []
    for key, now in after.items():
        then = before.get(key)
        if then is None:
            changes.append(Change("new", key[0], key[1], None, now["verdict"]))
            continue
        differs = _judged_otherwise(then, now)
        kind = "not compared" if differs else _kind(then["ok"], now["ok"])
        changes.append(Change(kind, key[0], key[1], then["verdict"], now["verdict"], differs))
    missing = [key for key in before if key not in after]
    changes += [Change("missing", k[0], k[1], before[k]["verdict"], None) for k in missing]
    notes = []
    if baseline.harness != __version__:
        notes.append(
            f"the baseline comes from fossbot-hil {baseline.harness}, this is {__version__}: "
            "a verdict may have changed with the harness"
        )
    new = [_label(k) for k in after if k not in before]
    if new or missing:
        gone = [_label(k) for k in missing]
        parts = [f"{len(new)} new ({', '.join(new)})"] if new else []
        parts += [f"{len(gone)} not run now ({', '.join(gone)})"] if gone else []
        notes.append("the baseline ran other scenarios: " + "; ".join(parts))
    otherwise = [c for c in changes if c.kind == "not compared"]
    if otherwise:
        fields = sorted({part.split()[0] for c in otherwise for part in c.reason.split("; ")})
        notes.append(
            f"{len(otherwise)} judged with another {' and '.join(fields)} in the baseline, "
            "so not compared"
        )
    return Comparison(baseline.path, baseline.harness, tuple(notes), tuple(changes))


def with_comparison(summary: Mapping[str, Any], comparison: Comparison) -> dict[str, Any]:
    """`summary` with each scenario's `change` and the comparison as `baseline`."""
    entries = [
        {**entry, "change": change.kind}
        for entry, change in zip(summary["scenarios"], comparison.changes, strict=False)
    ]
    return {**summary, "scenarios": entries, "baseline": comparison.as_json()}
