"""What a student may see of their grading: hidden scenarios by label, no instructor paths.

A hidden scenario is judged like any other, but the student's own files
(report, run.log, junit.xml) carry only its label and whether it passed,
and its first failure only when the grading file allows: never its name,
file, world, plot or recording. The grader keeps the full results apart
(<out>/grader/). Texts that reach a student's files are also rid of the
instructor's absolute paths (the class folder, the output folder, the
harness, the Python), replaced by what a student recognises.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from harness.judge.records import RunResult

__all__ = ["HiddenRun", "HiddenScenario", "hidden_run", "scrub_folder", "scrub_text"]

TEXT_SUFFIXES = (".html", ".json", ".xml", ".log", ".txt", ".csv")
MAX_SCRUB_BYTES = 64 << 20  # a report file larger than this is left as it is


@dataclass(frozen=True)
class HiddenScenario:
    label: str  # what students see, e.g. "hidden 1"
    show_failure: bool = False


@dataclass
class HiddenRun(RunResult):
    """A hidden scenario's result as a student's report shows it: no ticks, no world."""

    passed: bool = True
    answer_wrong: bool = False  # FAIL (an answer was wrong) rather than ERROR (the run broke)
    shown_failure: str | None = None

    @property
    def ok(self) -> bool:  # type: ignore[override]
        return self.passed

    @property
    def broken(self) -> bool:  # type: ignore[override]
        return not self.passed and not self.answer_wrong

    @property
    def first_failure(self) -> str | None:  # type: ignore[override]
        return self.shown_failure


def hidden_run(result: RunResult, hidden: HiddenScenario) -> HiddenRun:
    """`result` as a student sees it: the label, the verdict, the failure only if allowed."""
    failure = None
    if not result.ok:
        failure = f"{hidden.label}: failed"
        if hidden.show_failure and result.first_failure:
            failure = result.first_failure.replace(result.scenario, hidden.label)
    return HiddenRun(
        scenario=hidden.label,
        link=result.link,
        seed=0,
        threshold=result.threshold,
        faults="hidden",
        error=failure,
        not_started=result.not_started,
        not_run=result.not_run,
        passed=result.ok,
        answer_wrong=bool(result.failed_ticks),
        shown_failure=failure,
    )


def scrub_text(text: str, replacements: Sequence[tuple[str, str]]) -> str:
    """`text` with each (old, new) replaced, the longest `old` first (so a folder inside
    another is replaced by its own name, not its parent's)."""
    for old, new in sorted(replacements, key=lambda pair: -len(pair[0])):
        if old:
            text = text.replace(old, new)
    return text


def scrub_folder(folder: Path, replacements: Sequence[tuple[str, str]]) -> int:
    """Rewrite the text files under `folder` with `replacements`; how many changed."""
    changed = 0
    for path in sorted(folder.rglob("*")):
        if path.suffix not in TEXT_SUFFIXES or not path.is_file() or path.is_symlink():
            continue
        try:
            if path.stat().st_size > MAX_SCRUB_BYTES:
                continue
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        new = scrub_text(text, replacements)
        if new != text:
            from harness.atomic_write import write_atomically

            write_atomically(path, new.encode("utf-8"))
            changed += 1
    return changed
