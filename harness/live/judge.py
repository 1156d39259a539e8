"""Judging a node while the robot drives: every scan, on what came back before the next.

Live, nothing waits for the node. An answer belongs to the newest scan
published before it (DDS source timestamps: one clock on one machine); a
scan is judged once the next has gone out and a short grace has passed.
The oracle is the lockstep run's, the timing looser: ``fossbot-hil run``
stays the strict judge. Pure: no rclpy, no pybullet.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from harness.faults.link import ON_TIME
from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle, Verdict
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan

GRACE_NS = 50_000_000  # answers published before the next scan may still be in flight


@dataclass
class _Sent:
    tick: int
    t: float
    pose: tuple[float, float, float]
    scan: Scan
    sent_ns: int  # system clock, as DDS source timestamps are
    answers: Answers = field(default_factory=Answers)


class LiveJudge:
    """Collects the answers to each published scan and judges it when its window closes."""

    def __init__(
        self,
        oracle: Oracle,
        result: RunResult,
        *,
        on_tick: Callable[[TickRecord], None] | None = None,
    ) -> None:
        self.oracle = oracle
        self.result = result
        self.on_tick = on_tick
        self._open: list[_Sent] = []  # published, not yet judged, oldest first
        self.unmatched = 0  # answers to no open scan: before the first, or to one already judged

    def sent(
        self, tick: int, t: float, pose: tuple[float, float, float], scan: Scan, sent_ns: int
    ) -> None:
        """Scan `tick` went out at `sent_ns` (system clock, ns)."""
        self._open.append(_Sent(tick, t, pose, scan, sent_ns))

    def heard(self, kind: str, value: str | bool, source_ns: int) -> None:
        """An answer the node published at `source_ns`: it answers the newest scan before it."""
        owner = next((s for s in reversed(self._open) if s.sent_ns <= source_ns), None)
        if owner is None:
            self.unmatched += 1
            return
        received = Received(value, max(0.0, (source_ns - owner.sent_ns) / 1e9), source_ns=source_ns)
        lists = {"status": owner.answers.statuses, "warning": owner.answers.warnings}
        lists.get(kind, []).append(received)  # any other kind: no answer to judge

    def settle(self, now_ns: int, *, final: bool = False) -> list[Verdict]:
        """Judge every scan whose window has closed by `now_ns` (all of them when `final`)."""
        verdicts = []
        while self._open:
            current = self._open[0]
            following = self._open[1] if len(self._open) > 1 else None
            closes = following.sent_ns if following is not None else None
            if not final and (closes is None or now_ns < closes + GRACE_NS):
                break
            self._open.pop(0)
            window = ((closes or now_ns) - current.sent_ns) / 1e9
            verdicts.append(self._judge(current, window))
        return verdicts

    def _judge(self, sent: _Sent, window: float) -> Verdict:
        answers = sent.answers
        answers.waited = window
        answers.timed_out = not answers.statuses
        verdict = self.oracle.judge(sent.tick, sent.t, sent.scan, answers, ON_TIME)
        record = TickRecord(
            sent.tick, sent.t, *sent.pose, sent.scan, answers.clipped(), verdict.clipped(), ON_TIME
        )
        self.result.records.append(record)
        if self.on_tick is not None:
            self.on_tick(record)
        return verdict
