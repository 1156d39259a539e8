"""Watchdogs over a node's answers: silence, flood and strangers, judged from counts alone.

Each ends a run the node cannot go on with and names the problem in the node's
terms; none waits, spins or imports rclpy, so each is tested on its own."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from harness.judge.answers import Answers

STOPPED_AFTER = 3  # consecutive missed deadlines end the run
FLOOD_SCANS = 5  # a flood is judged over this many recent scans, in which a topic carried
FLOOD_PER_SCAN = 5  # more than this many messages a scan,
FLOOD_MIN = 30  # this many at least,
FLOOD_RATE_HZ = 200.0  # and this many a second (a 10 Hz timer during long waits is no flood)


@dataclass(frozen=True)
class Topics:
    """What the node under test is, and the topics it reads and answers on (for messages)."""

    node: str  # the node's description, e.g. "python3 lidar_node.py"
    scan: str
    status: str
    warning: str


@dataclass
class SilenceWatch:
    """Ends the run when the node misses its deadline on STOPPED_AFTER scans in a row."""

    topics: Topics
    scan_timeout: float
    scans: int = 0  # scans in a row whose deadline passed
    empty: int = 0  # of those, scans with no valid return
    bools: int = 0  # Bools the node published for them (so it is not stuck)
    answered_empty: bool = False  # the node answered a scan with no valid return
    late_in_streak: tuple[int, float] | None = None  # (tick, after) of a late answer

    def see(self, answers: Answers, tick: int, *, empty: bool = False) -> None:
        """Count this scan's answers (`empty`: it had no valid return); past the limit,
        set `answers.problem` and mark the node silent (its silence is its verdict)."""
        if not answers.timed_out:
            self.scans = self.empty = self.bools = 0
            self.late_in_streak = None
            self.answered_empty = self.answered_empty or (empty and bool(answers.statuses))
            return
        self.scans += 1
        self.empty += empty
        self.bools += sum(1 for r in answers.late if r.tick == tick and isinstance(r.value, bool))
        came_late = [r for r in answers.late if r.tick == tick and isinstance(r.value, str)]
        if came_late:
            self.late_in_streak = (tick, came_late[0].after)
        if self.scans < STOPPED_AFTER or answers.problem is not None:
            return
        answers.problem = self._why(came_late[0].after if came_late else None)
        answers.silent = True

    def _why(self, last_late_after: float | None) -> str:
        t = self.topics
        missed = f"{self.scans} scans in a row missed the {self.scan_timeout:g} s deadline"
        if last_late_after is not None:
            last = f"the last answer came after {last_late_after:.2f} s"
            return f"node answers too late: {missed} ({last})"
        if self.late_in_streak is not None:
            # Slow, not stopped: an earlier scan of the streak was answered, late, and this
            # one's answer had not come when the harness stopped waiting for it.
            late_tick, after = self.late_in_streak
            return (
                f"node answers too late: {missed} (tick {late_tick}'s answer came after "
                f"{after:.2f} s; the last scan's had not come when the harness stopped waiting)"
            )
        if self.empty == self.scans and not self.answered_empty:
            return (
                f"node {t.node} is running and subscribed to {t.scan} but published nothing on "
                f"{t.status} for {self.scans} scans in a row, none of which had a valid return: "
                'a status is expected when nothing is in range too (e.g. "no obstacle")'
            )
        if self.bools:
            return (
                f"node stopped answering: no status on {t.status} for {self.scans} scans in a "
                f"row, though it published {t.warning} for them (it is running and not stuck in "
                "a callback: its status is not published for every scan)"
            )
        return (
            f"node stopped answering: no status on {t.status} for {self.scans} scans in a row "
            "(the node is still running: stuck in a callback, or not publishing)"
        )


@dataclass
class FloodWatch:
    """Ends the run when the node publishes far more than one message a scan on a topic."""

    status_topic: str
    warning_topic: str
    counted: tuple[int, int] = (0, 0)  # statuses and Bools heard, all told, at the last count
    # (statuses, Bools, seconds) of each recent exchange
    recent: deque[tuple[int, int, float]] = field(default_factory=lambda: deque(maxlen=FLOOD_SCANS))

    def restart(self, statuses: int, bools: int) -> None:
        """Count from here: what was heard so far (warm-up, the first scan's copies) is no flood."""
        self.counted = (statuses, bools)

    def see(self, answers: Answers, statuses: int, bools: int, seconds: float) -> None:
        """One exchange ended after `seconds`, with these totals heard; name a flood in
        `answers.problem` unless it already has one."""
        self.recent.append((statuses - self.counted[0], bools - self.counted[1], seconds))
        self.counted = (statuses, bools)
        if answers.problem is not None:
            return
        seconds = sum(recent[2] for recent in self.recent)
        for which, topic in enumerate((self.status_topic, self.warning_topic)):
            count = sum(recent[which] for recent in self.recent)
            many = count >= FLOOD_MIN and count > FLOOD_PER_SCAN * len(self.recent)
            if many and count >= FLOOD_RATE_HZ * seconds:
                answers.problem = (
                    f"node floods {topic}: {count} messages in {seconds:.2f} s over the last "
                    f"{len(self.recent)} scans (one per scan expected)"
                )
                return


def strangers_problem(crowd: str, domain_id: int | None) -> str | None:
    """Why a scan got several answers when it is not the node's doing: someone else in
    this run's domain (then the run is the harness's problem, not the node's)."""
    if not crowd:
        return None
    domain = f" ({domain_id})" if domain_id is not None else ""
    return (
        f"another ROS node shares this run's domain{domain}: {crowd}; "
        "the answers cannot be told apart (a node left running by an earlier run, or "
        "one started with this ROS_DOMAIN_ID)"
    )
