"""What came back from the software under test for one scan (pure)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from harness.safe_text import TEXT_LIMIT, for_storage

if TYPE_CHECKING:  # numpy, for the type only
    from harness.lidar.scan import Scan


@dataclass(frozen=True)
class Received:
    """One message from the node: a status String or a warning Bool."""

    value: str | bool
    after: float  # seconds between sending the scan and this message arriving
    tick: int | None = None  # the scan it answers, when it arrived late (see Answers.late)
    source_ns: int = 0  # when the node published it (DDS source timestamp), when known


@dataclass
class Answers:
    """Everything that arrived for one scan, and how the wait for it ended."""

    statuses: list[Received] = field(default_factory=list)
    warnings: list[Received] = field(default_factory=list)
    waited: float = 0.0  # seconds the link waited for this scan's answers
    timed_out: bool = False  # the per-scan deadline passed without a status
    problem: str | None = None  # link-level failure, e.g. "node exited with code 1: ..."
    crashed: bool = False  # `problem` is the software under test's own: it exited, crashed,
    # or (a processing function) raised or hung; not the link's
    # `problem` is the node's silence: it runs, but answered too late or not at all. That
    # ends the run and is the node's verdict (FAIL), not a break of the run (ERROR).
    silent: bool = False
    late: list[Received] = field(default_factory=list)  # answers to earlier scans, by tick
    seen: Scan | None = None  # the scan the node received, when a device and driver made it
    lost: str | None = None  # why the node never got this scan (e.g. damaged on the line)
    # Earlier driver scans the node answered during this exchange (a revolution the
    # line made late, or split), each with its own answers: judged on their own.
    earlier: list[tuple[Scan, Answers]] = field(default_factory=list)
    # The node owed answers to scans before this one when it went (a board's idle stream,
    # copies of the first scan) and answers in order: of its answers, late ones included,
    # the newest is this tick's (see take_late).
    owed_before: bool = False

    def clipped(self, limit: int = TEXT_LIMIT) -> Answers:
        """A copy to keep: each text clipped to `limit`, storable (judged as it arrived)."""

        def kept(items: list[Received]) -> list[Received]:
            return [
                replace(r, value=for_storage(r.value, limit)) if isinstance(r.value, str) else r
                for r in items
            ]

        return replace(
            self,
            statuses=kept(self.statuses),
            warnings=list(self.warnings),
            problem=None if self.problem is None else for_storage(self.problem, limit),
            late=kept(self.late),
            lost=None if self.lost is None else for_storage(self.lost, limit),
            earlier=[(scan, answers.clipped(limit)) for scan, answers in self.earlier],
        )

    @property
    def extra_scans(self) -> int:
        return len(self.earlier)

    def first_answer_only(self) -> None:
        """Several copies of one scan went out (a repeat, a resent first scan) and the node
        answered more than one: its first status (and the Bools published nearest to it)
        answer this tick; the later ones answer the copies, kept as late answers of no
        tick, never judged."""
        statuses = sorted(self.statuses, key=lambda r: r.source_ns)
        self.keep_only(statuses[:1])

    def keep_only(self, kept: list[Received]) -> None:
        """Only the statuses `kept` (and the Bools published nearest to them) answer this
        tick; the others, and their Bools, become late answers of no tick."""
        statuses = sorted(self.statuses, key=lambda r: r.source_ns)
        if not statuses:
            return
        others = [r for r in statuses if r not in kept]
        self.statuses = [r for r in statuses if r in kept]
        bools = []
        for item in self.warnings:
            nearest = min(statuses, key=lambda r: abs(r.source_ns - item.source_ns))
            (bools if nearest in kept else others).append(item)
        self.warnings = bools
        self.late += [replace(r, tick=None) for r in others]

    def take_late(self, late: list[Received], tick: int) -> list[Received]:
        """Adopt the late answers that belong to `tick`; return the others.

        An answer to a scan whose deadline had passed stays late: it must
        not turn a timeout into a pass. When the node `owed_before`, a late
        status is a newer answer than the ones held: it is this tick's, and
        those become late answers of no tick.
        """
        rest, adopted = [], False
        for item in late:
            if item.tick != tick:
                rest.append(item)
            elif self.timed_out:
                self.late.append(item)
            elif isinstance(item.value, bool):
                self.warnings.append(item)
            else:
                self.statuses.append(item)
                adopted = True
        if adopted and self.owed_before:
            self.keep_only(sorted(self.statuses, key=lambda r: r.source_ns)[-1:])
        return rest
