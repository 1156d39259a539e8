"""Run results as plain JSON-ready data: one entry per scenario, one per tick (pure).

The same words the terminal table shows (PASS, FAIL, ERROR, NOT RUN), so a
CI script reading summary.json and a person reading the table agree.
Non-finite floats (a status saying "inf") become the strings "inf", "-inf"
and "nan": the files stay strict JSON that any parser reads.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from harness import __version__
from harness.judge.records import RunResult, TickRecord
from harness.judge.verdicts import verdict_of
from harness.safe_text import for_storage

if TYPE_CHECKING:
    from harness.judge.alignment import Alignment

__all__ = [
    "FORMAT", "alignment_entry", "alignment_fails", "coverage_entry", "json_bytes", "run_summary",
    "scenario_details", "scenario_entry", "tick_entry",
]  # fmt: skip

FORMAT = 1  # bump when a key changes meaning or disappears (docs/reports.md)


def _number(x: float | None) -> float | str | None:
    if x is None:
        return None
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def scenario_entry(result: RunResult, files: Mapping[str, str | None]) -> dict[str, Any]:
    """One scenario as summary.json lists it; `files` maps artifact names to paths."""
    failed = result.failed_ticks
    return {
        "scenario": result.scenario,
        "verdict": verdict_of(result),
        "ok": result.ok,
        "link": result.link,
        "seed": result.seed,
        "threshold": _number(result.threshold),
        "warning_when_clear": result.warning_rule,
        "faults": result.faults,
        "ticks": len(result.records),
        "failed": len(failed),
        "failed_ticks": [r.tick for r in failed],
        "first_failure": result.first_failure,
        "error": result.error,
        "notes": list(result.notes),  # how the node is wired, its launch files: the run's
        "wall_s": round(result.wall_s, 3),  # the run itself
        "startup_s": round(result.startup_s, 3),  # waiting for the node to come up
        "stop_s": round(result.stop_s, 3),  # waiting for it to stop
        "total_s": round(result.total_s, 3),  # what the scenario cost the run
        "gap_s": None if result.gap_s is None else _number(round(result.gap_s, 3)),
        "files": dict(files),
    }


def tick_entry(record: TickRecord) -> dict[str, Any]:
    """One tick: pose, what a correct node says, what this node said, what failed."""
    v = record.verdict
    exp = v.expected
    claim = v.claim
    answers = record.answers
    return {
        "tick": record.tick,
        "t": _number(record.t),
        "pose": [_number(record.x), _number(record.y), _number(record.yaw)],
        "ok": v.ok,
        "expected": {
            "obstacle": exp.obstacle,
            "distance": _number(exp.distance),
            "angle": _number(exp.angle),
            "index": exp.index,
            "warning": exp.warning,
        },
        "status": claim.text if claim is not None else None,
        "claim": None
        if claim is None
        else {
            "obstacle": claim.obstacle,
            "distance": _number(claim.distance),
            "angle": _number(claim.angle),
        },
        "warning": v.warning_got,
        "waited_s": round(answers.waited, 4),
        "timed_out": answers.timed_out,
        "scan_seen_from_device": answers.seen is not None,
        "delivery": {
            "kind": record.delivery.kind,
            "delay_s": round(record.delivery.delay_s, 4),
            "stamp_age_s": _number(record.delivery.stamp_age_s),
            "lost_on_line": answers.lost,
            "driver_scans": 1 + answers.extra_scans if answers.seen is not None else None,
        },
        "failures": list(v.failures),
    }


def scenario_details(result: RunResult, files: Mapping[str, str | None]) -> dict[str, Any]:
    """The per-scenario file: its summary entry, the node's output, every tick."""
    return {
        "format": FORMAT,
        **scenario_entry(result, files),
        "diagnostics": result.diagnostics,
        "records": [tick_entry(r) for r in result.records],
    }


def passed_line(passed: int, total: int) -> str:
    """'6 of 7 scenarios passed', '0 of 1 scenario passed'."""
    return f"{passed} of {total} scenario{'s' if total != 1 else ''} passed"


def alignment_fails(alignment: Alignment | None, mode: str = "warn") -> bool:
    """`--alignment fail` and the board's /scan is the truth turned or mirrored."""
    return mode == "fail" and alignment is not None and alignment.misaligned


def alignment_entry(alignment: Alignment | None, mode: str = "warn") -> dict[str, Any] | None:
    """summary.json's `alignment`: the fitted turn and mirror of the board's /scan, if any."""
    if alignment is None:
        return None
    return {
        "status": alignment.status,
        "rotation_deg": _number(alignment.rotation_deg),
        "mirrored": alignment.mirrored,
        "ticks": alignment.ticks,
        "agreement": _number(alignment.agreement),
        "identity_agreement": _number(alignment.identity_agreement),
        "fix": for_storage(alignment.fix),
        "reason": for_storage(alignment.reason),
        "text": for_storage(alignment.text()),
        "mode": mode,
        "fails_run": alignment_fails(alignment, mode),
    }


def coverage_entry(results: Sequence[RunResult]) -> dict[str, Any]:
    """summary.json's `coverage`: which kinds of readings the delivered scans carried,
    in total and per scenario, and what the suite never delivered (`gaps`)."""
    from harness.judge.reading_coverage import (
        ANGLE_MARGIN_RAD,
        NEAR_THRESHOLD_M,
        coverage_by_scenario,
        coverage_of,
        gaps,
    )

    total = coverage_of(results)
    return {
        "near_threshold_m": NEAR_THRESHOLD_M,
        "angle_near_pi_rad": ANGLE_MARGIN_RAD,
        "total": total.as_dict(),
        "scenarios": {name: c.as_dict() for name, c in coverage_by_scenario(results).items()},
        "gaps": gaps(total),
    }


def run_summary(
    entries: Sequence[dict[str, Any]],
    wall_s: float | None = None,
    *,
    alignment: Alignment | None = None,
    alignment_mode: str = "warn",
    coverage: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """summary.json: totals first (what CI checks), then every scenario. `wall_s` is the
    command's wall time (else the scenarios' sum); a misaligned board's /scan with
    `alignment_mode` "fail" makes the run not `ok`, as it makes the exit code 1."""
    passed = sum(1 for e in entries if e["ok"])
    return {
        "format": FORMAT,
        "harness": __version__,
        "ok": passed == len(entries) and not alignment_fails(alignment, alignment_mode),
        "total": len(entries),
        "passed": passed,
        "failed": len(entries) - passed,
        "wall_s": round(wall_s if wall_s is not None else sum(e["total_s"] for e in entries), 3),
        # Each scenario's notes once (the same wiring or launch file note in every one).
        "notes": list(dict.fromkeys(n for e in entries for n in e.get("notes", ()))),
        "alignment": alignment_entry(alignment, alignment_mode),
        "coverage": coverage,
        "scenarios": list(entries),
    }


def json_bytes(data: Any) -> bytes:
    """Strict, stable JSON (no NaN literals; keys in the order built)."""
    return (json.dumps(data, indent=2, allow_nan=False, ensure_ascii=False) + "\n").encode()
