"""What came back from the software under test for one scan (pure)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Received:
    """One message from the node: a status String or a warning Bool."""

    value: str | bool
    after: float  # seconds between sending the scan and this message arriving


@dataclass
class Answers:
    """Everything that arrived for one scan, and how the wait for it ended."""

    statuses: list[Received] = field(default_factory=list)
    warnings: list[Received] = field(default_factory=list)
    waited: float = 0.0  # seconds the link waited for this scan's answers
    timed_out: bool = False  # the per-scan deadline passed without a status
    problem: str | None = None  # link-level failure, e.g. "node exited with code 1: ..."
    late: list[Received] = field(default_factory=list)  # answers to an earlier scan
