"""Gradescope's autograder results (results.json) for one submission (pure).

Gradescope's documented format (gradescope-autograders.readthedocs.io, "Autograder
Specifications"): a JSON object with the total ``score`` (it overrides the sum of
the tests), optional ``execution_time`` (seconds), ``output`` (text about the
whole submission), ``visibility``, ``stdout_visibility``, ``output_format`` and
``test_output_format``/``test_name_format``, and ``tests``: one object per test
with ``score``, ``max_score``, ``status`` (``passed`` or ``failed``, which sets how
the test is shown whatever its score), ``name``, ``output`` and ``visibility``
(``visible``, ``hidden``, ``after_due_date``, ``after_published``).

One test per scenario, in the plan's order. A hidden scenario is a test named
by its label ("hidden 1") whose output says only "passed" or "failed" (or its
first failure, when the grading file allows): never its name, file or world.
Every text a student sees goes through student_text.for_students (no absolute
path of the grader's machine) and is shown as plain text (``text`` formats:
a node's output is never rendered as HTML). The autograder's stdout, which
holds the whole run, stays hidden from students.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from harness.grading.class_table import ERROR, FAIL, NOT_RUN, PASS
from harness.grading.scoring import ScorePlan
from harness.grading.student_text import for_students
from harness.safe_text import DIAGNOSTICS_LIMIT, TEXT_LIMIT, clip, visible

__all__ = ["VISIBILITIES", "gradescope_results", "not_graded_results"]

VISIBILITIES = ("visible", "hidden", "after_due_date", "after_published")
STATUSES = ("passed", "failed")
_IN_WORDS = {
    PASS: "passed",
    FAIL: "failed: an expectation did not hold",
    ERROR: "error: the run broke before the scenario ended",
    NOT_RUN: "not run",
}


def _points(value: float) -> float:
    """Points as Gradescope shows them: hundredths."""
    return round(float(value), 2)


def _text(text: str, hidden: Mapping[str, str], limit: int = TEXT_LIMIT) -> str:
    """A text for a student: no grader paths, hidden names as labels, nothing that moves
    a cursor, bounded."""
    return visible(clip(for_students(text, hidden_names=hidden), limit))


def _test_output(
    verdict: str, failure: str, ticks: tuple[int, int] | None, show_failure: bool, hidden: bool
) -> str:
    if hidden:
        if verdict == PASS:
            return "passed"
        return failure if show_failure and failure else "failed"
    lines = [failure or _IN_WORDS.get(verdict, verdict)]
    if ticks is not None and ticks[1] > 0:
        held, of = ticks
        lines.append(f"ticks held: {max(0, min(held, of))} of {of}")
    return "\n".join(lines)


def gradescope_results(
    plan: ScorePlan,
    verdicts: Mapping[str, str],
    ticks: Mapping[str, tuple[int, int]],
    failures: Mapping[str, str],
    *,
    notes: Sequence[str] = (),
    execution_time: float | None = None,
    output: str = "",
    hidden_names: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """results.json's object for one submission. `verdicts` (missing: NOT RUN), `ticks`
    (held, planned) and `failures` by scenario; `notes` and `output` go into the top-level
    output; `hidden_names` adds what else students must not read (a hidden scenario's file
    path -> its label) to the hidden scenarios' names, which are always replaced."""
    hidden = {s.name: s.shown_name for s in plan.scenarios if s.hidden}
    hidden.update(hidden_names or {})
    tests = []
    for entry in plan.scenarios:
        verdict = verdicts.get(entry.name, NOT_RUN)
        held = ticks.get(entry.name)
        failure = _text(failures.get(entry.name, ""), hidden) if verdict != PASS else ""
        text = _test_output(verdict, failure, held, entry.show_failure, entry.hidden)
        tests.append(
            {
                "name": _text(entry.shown_name, hidden, 200),
                "score": _points(plan.earned(entry.name, verdict, held)),
                "max_score": _points(plan.max_points(entry.name)),
                "status": "passed" if verdict == PASS else "failed",
                "output": text,
                "visibility": "visible",
            }
        )
    about = [f"note: {n}" for n in notes if n.strip()]
    if output.strip():
        about.append(output)
    results: dict[str, Any] = {"score": _points(plan.score(verdicts, ticks))}
    if execution_time is not None:
        results["execution_time"] = max(0, round(execution_time))
    results.update(
        {
            "output": _text("\n".join(about), hidden, DIAGNOSTICS_LIMIT),
            "output_format": "text",
            "test_output_format": "text",
            "test_name_format": "text",
            "stdout_visibility": "hidden",
            "tests": tests,
        }
    )
    return results


def not_graded_results(
    plan: ScorePlan, reason: str, *, execution_time: float | None = None
) -> dict[str, Any]:
    """results.json for a submission that could not be run at all (it did not build, no
    node was found, the harness failed): every scenario 0 points and failed, `reason`
    in the top-level output and on the first test."""
    first = plan.scenarios[0].name if plan.scenarios else None
    why = f"not graded: {reason}"
    failures = {first: why} if first is not None else {}
    verdicts = {s.name: ERROR if s.name == first else NOT_RUN for s in plan.scenarios}
    for s in plan.scenarios[1:]:
        failures[s.name] = "not run"
    return gradescope_results(
        plan, verdicts, {}, failures, execution_time=execution_time, output=why
    )
