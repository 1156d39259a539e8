"""What an audit says: the kill matrix on the terminal, and the one JSON object of --json."""

from __future__ import annotations

from typing import Any

from rich.console import Console
from rich.table import Table

from harness.audit.matrix import KillMatrix
from harness.audit.mutants import mutant_named
from harness.audit.suite_audit import AuditOutcome
from harness.judge.reading_coverage import CASE_NAMES, CASES, other_counts
from harness.option_names import worded

__all__ = ["LEGEND", "audit_json", "exit_code", "print_audit", "score_line"]

MARKS = {"killed": "x", "survived": ".", "flip": "~", "not run": "!"}
LEGEND = "x killed in every seed, . passed, ~ the verdict changed with the seed, ! could not run"


def audit_json(outcome: AuditOutcome, *, repeat: int, seeds: list[int | None]) -> dict[str, Any]:
    """`mutants` (name, mistake, status, killed_by, error), `survivors`, `errors`, `score`
    (of the mutants judged), `coverage`, `flips`, and the rest."""
    matrix = outcome.matrix
    killed, judged = matrix.score
    return {
        "scenarios": list(matrix.scenarios),
        "repeat": repeat,
        "seeds": seeds,
        "mutants": [
            {
                "name": name,
                "mistake": mutant_named(name).mistake,
                "status": matrix.status(name),
                "killed_by": list(matrix.killed_by[name]),
                "first_failure": matrix.why.get(name, ""),
                "error": matrix.unit_errors.get(name),
            }
            for name in matrix.mutants
        ],
        "survivors": list(matrix.survivors),
        "errors": list(matrix.errors),
        "score": {
            "killed": killed,
            "judged": judged,
            "errors": len(matrix.errors),
            "mutants": len(matrix.mutants),
        },
        "coverage": outcome.coverage,
        "coverage_gaps": outcome.coverage_gaps,
        "flips": [flip.as_dict() for flip in matrix.flips],
        "correct_node_failed": matrix.unsound,
        "correct_node_not_run": sorted(matrix.unjudged),
        "unit_errors": matrix.unit_errors,
    }


def _say(console: Console, text: str = "") -> None:
    console.print(text, markup=False, highlight=False)


def _matrix_table(matrix: KillMatrix) -> Table:
    table = Table(box=None, pad_edge=False, header_style="bold")
    table.add_column("mistake", no_wrap=True)
    for i, _ in enumerate(matrix.scenarios, start=1):
        table.add_column(str(i), justify="center")
    table.add_column("killed by", justify="right")
    for name in matrix.mutants:
        marks = [MARKS[matrix.cells[name, s]] for s in matrix.scenarios]
        count = len(matrix.killed_by[name])
        status = matrix.status(name)
        table.add_row(name, *marks, str(count) if count else status.upper())
    return table


def _coverage_lines(coverage: dict[str, Any]) -> list[str]:
    if not coverage:
        return ["(the correct node's run gave no coverage)"]
    width = max(len(name) for name in CASE_NAMES.values())
    lines = [f"scans delivered: {coverage['scans']}"]
    lines.append(f"  {'reading':<{width}}  beside a valid return  without one")
    for case in CASES:
        counts = coverage["cases"][case]
        beside, without = counts["beside_valid"], counts["without_valid"]
        lines.append(f"  {CASE_NAMES[case]:<{width}}  {beside:>22}  {without:>11}")
    lines.extend(f"  {words}: {count}" for words, count in other_counts(coverage))
    return lines


def print_audit(console: Console, outcome: AuditOutcome) -> None:
    """The matrix (x killed, . survived, ~ flips), survivors, coverage, flips, and the score."""
    matrix = outcome.matrix
    _say(console)
    _say(console, "scenarios: " + ", ".join(f"{i} {s}" for i, s in enumerate(matrix.scenarios, 1)))
    console.print(_matrix_table(matrix))
    _say(console, LEGEND)
    for scenario, why in matrix.unsound.items():
        if scenario in matrix.unjudged:
            _say(console, f"the correct node could not run {scenario}, so it judges nothing: {why}")
        else:
            _say(console, f"the correct node fails {scenario}, so it kills nothing: {why}")
    if matrix.unit_errors:
        _say(console)
        _say(console, "could not run (neither killed nor passed):")
        for name, why in matrix.unit_errors.items():
            _say(console, f"  {name}: {why}")
    if matrix.survivors:
        _say(console)
        _say(console, "mistakes no scenario catches, and what would catch them:")
        for name in matrix.survivors:
            mutant = mutant_named(name)
            _say(console, f"  {name}: {mutant.mistake}; caught by {worded(mutant.caught_by)}")
    if matrix.flips:
        _say(console)
        _say(console, "verdicts that changed with the seed:")
        for flip in matrix.flips:
            _say(console, f"  {flip.mutant} in {flip.scenario}: {' '.join(flip.verdicts)}")
    _say(console)
    _say(console, "readings the suite delivered (the correct node's run):")
    for line in _coverage_lines(outcome.coverage):
        _say(console, line)
    for gap in outcome.coverage_gaps:
        _say(console, f"  gap: {gap}")
    _say(console)
    _say(console, score_line(matrix))


def score_line(matrix: KillMatrix) -> str:
    """The score, of the mutants judged: what could not run is said, not counted."""
    killed, judged = matrix.score
    errors = len(matrix.errors)
    if not errors:
        return f"score: the suite catches {killed} of {judged} mistakes"
    if not judged:
        return f"score: none: the audit could not run any of the {errors} mistakes"
    return (
        f"score: the suite catches {killed} of the {judged} mistakes that ran "
        f"({errors} could not run)"
    )


def exit_code(matrix: KillMatrix) -> int:
    """0 when every mistake ran and was caught; 1 when one survives, the correct node
    fails or could not run a scenario, or a unit could not run."""
    return 1 if matrix.survivors or matrix.unsound or matrix.unit_errors else 0
