"""Which answer answered which driver scan, when one revolution brought several.

Pure: a damaged line can make a revolution late (its scan comes with the
next one's) or split it in two; the node answers scans in order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from harness.judge.answers import Answers
from harness.lidar.scan import Scan

if TYPE_CHECKING:
    from harness.ros.observer import Heard

__all__ = ["AnswerWindow", "owed_answers", "pair_with_driver_scans"]


def pair_with_driver_scans(answers: Answers, scans: list[Heard]) -> None:
    """Give each answer the driver scan it answered.

    A damaged line may make a revolution late (its scan comes with the next) or split
    it, so several scans come before the node answers any. The node answers in order:
    the i-th status answers the i-th scan, and with as many Bools the i-th Bool goes
    with it; otherwise (Bools on change only) each Bool goes with the nearest status
    (nearness alone misleads when callbacks run back to back on a loaded machine). The
    newest scan is this tick's; the earlier go, with their answers, to ``answers.earlier``."""
    if len(scans) < 2:
        return
    seen = [h.value for h in scans if isinstance(h.value, Scan)]
    groups = [Answers(seen=scan, waited=answers.waited) for scan in seen]
    statuses = sorted(answers.statuses, key=lambda r: r.source_ns)
    for i, item in enumerate(statuses):
        groups[min(i, len(groups) - 1)].statuses.append(item)
    warnings = sorted(answers.warnings, key=lambda r: r.source_ns)
    for i, item in enumerate(warnings):
        if not statuses:
            status = len(groups) - 1
        elif len(warnings) == len(statuses):
            status = i
        else:
            status = min(
                range(len(statuses)), key=lambda j: abs(statuses[j].source_ns - item.source_ns)
            )
        groups[min(status, len(groups) - 1)].warnings.append(item)
    answers.statuses, answers.warnings = groups[-1].statuses, groups[-1].warnings
    answers.seen = seen[-1]
    answers.earlier = list(zip(seen[:-1], groups[:-1], strict=True))


@dataclass(frozen=True)
class AnswerWindow:
    """What one tick's exchange leaves the next to account for: the driver scans from the
    tick's own on (its own and the device's repeats of it) and the statuses heard for them."""

    scans: int
    statuses: int


def owed_answers(window: AnswerWindow | None, repeats_before: int, late_before: int) -> int:
    """How many statuses published after this tick's driver scan still answer earlier ones.

    In real time the device repeats a revolution while the harness is late, and a node
    answering in order may answer a repeat only after the next tick's scan came: that
    answer is not the tick's. The scans since the last tick's own (`window`, plus
    `repeats_before`) less the statuses heard for them (`late_before`) is what is owed,
    at most one a repeat. No window (first tick, a lost revolution, a damaged line,
    copies of the first scan) owes nothing."""
    if window is None:
        return 0
    repeats = window.scans - 1 + repeats_before
    return min(repeats, max(0, window.scans + repeats_before - window.statuses - late_before))
