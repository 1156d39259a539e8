"""What ``hil.run`` returns: a RunResult with the reading a failing test needs (pure).

``assert result.ok, result.explanation`` prints the first failed tick's explanation,
how many more failed, why the run ended and the node's last stderr when it crashed or
went quiet; the short ``repr`` serves a bare assert. Both bounded and escaped."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from harness.safe_text import DIAGNOSTICS_LIMIT, TEXT_LIMIT, clip, for_terminal

if TYPE_CHECKING:
    from harness.judge.records import RunResult, TickRecord

__all__ = ["HilResult"]

REPR_CHARS = 160  # of the scenario and link names, in repr
LISTED_TICKS = 10  # further failed ticks named by number


@dataclass(frozen=True)
class HilResult:
    """One scenario run through one link, judged tick by tick."""

    raw: RunResult
    domain_id: int | None = None  # the ROS domain the run used (None: no ROS graph)

    @property
    def ok(self) -> bool:
        """Every tick passed and nothing ended the run early."""
        return self.raw.ok

    @property
    def records(self) -> list[TickRecord]:
        return self.raw.records

    @property
    def failed_ticks(self) -> list[TickRecord]:
        return self.raw.failed_ticks

    @property
    def scenario(self) -> str:
        return self.raw.scenario

    def _title(self) -> str:
        r = self.raw
        return (
            f"{r.scenario} over {r.link} (seed {r.seed}, faults {r.faults or 'clean'}, "
            f"threshold {r.threshold:g} m)"
        )

    def _node_output_matters(self) -> bool:
        """The node's stderr explains a crash, a start-up failure or silence, not a wrong value."""
        return self.raw.error is not None or any(r.verdict.claim is None for r in self.failed_ticks)

    @property
    def explanation(self) -> str:
        """Readable text: the first failure, how many more, the run error, the node's stderr."""
        r = self.raw
        failed = self.failed_ticks
        if self.ok:
            return for_terminal(f"{self._title()}: all {len(r.records)} ticks passed")
        error = clip(r.error, TEXT_LIMIT) if r.error is not None else None
        if r.not_started:
            lines = [f"{self._title()}: did not start: {error}"]
        else:
            lines = [f"{self._title()}: {len(failed)} of {len(r.records)} ticks failed"]
        if failed:
            lines.append(f"first failure: {failed[0].verdict.explanation}")
            more = [str(t.tick) for t in failed[1 : 1 + LISTED_TICKS]]
            if len(failed) > 1:
                etc = ", ..." if len(failed) > 1 + LISTED_TICKS else ""
                lines.append(f"{len(failed) - 1} more failed ticks: {', '.join(more)}{etc}")
        if r.error is not None and not r.not_started:
            problem = r.error.partition(": ")[2] or r.error  # without its "t=... tick N: "
            if not failed or clip(problem) not in failed[0].verdict.explanation:
                lines.append(f"the run ended early: {error}")
        if r.diagnostics and self._node_output_matters():
            lines.append(clip(r.diagnostics, DIAGNOSTICS_LIMIT).rstrip())
        return for_terminal("\n".join(lines))

    def check(self) -> HilResult:
        """Raise AssertionError with the explanation unless ok; returns self to chain."""
        if not self.ok:
            raise AssertionError(self.explanation)
        return self

    def __repr__(self) -> str:
        r = self.raw
        where = for_terminal(clip(f"{r.scenario} over {r.link}", REPR_CHARS))
        if self.ok:
            return f"<HilResult {where}: PASS, {len(r.records)} ticks>"
        count = f"{len(self.failed_ticks)} of {len(r.records)} ticks failed"
        if r.not_started:
            count = "did not start"
        elif r.error is not None and not self.failed_ticks:
            count = "ended early"
        # No explanation here: `assert result.ok, result.explanation` prints it already,
        # and assertion rewriting prints this repr beside it.
        return f"<HilResult {where}: FAIL, {count}>"

    def __str__(self) -> str:
        return self.explanation
