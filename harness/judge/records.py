"""What one run produced, tick by tick (pure records)."""

from __future__ import annotations

from dataclasses import dataclass, field

from harness.faults.link import ON_TIME, Delivery
from harness.judge.answers import Answers
from harness.judge.oracle import Verdict
from harness.judge.run_hints import run_hint
from harness.lidar.mount import LidarMount
from harness.lidar.scan import Scan


@dataclass(frozen=True)
class TickRecord:
    """One scan: where the robot was, what was sent, what came back, the verdict."""

    tick: int
    t: float
    x: float
    y: float
    yaw: float
    scan: Scan
    answers: Answers
    verdict: Verdict
    delivery: Delivery = ON_TIME  # how the link carried it (link faults)


@dataclass
class RunResult:
    """A scenario run through one link. `error` ends a run before its last tick."""

    scenario: str
    link: str
    seed: int
    threshold: float
    faults: str
    noise_sigma: float = 0.0  # the fault profile's noise, which widens the oracle's band
    warning_rule: str = "optional"  # "required": warning False was due on every clear scan
    records: list[TickRecord] = field(default_factory=list)
    error: str | None = None
    diagnostics: str = ""  # e.g. the node's last stderr lines, shown on failure
    # How the software under test is wired, true of the whole run (e.g. its warning on
    # another topic, and the option that names it): reports print each once.
    notes: list[str] = field(default_factory=list)
    wall_s: float = 0.0  # the run itself: simulating, exchanging, judging
    startup_s: float = 0.0  # waiting for the software under test to come up (in series)
    stop_s: float = 0.0  # waiting for it to stop, after the run (in series)
    not_started: bool = False  # the software under test never came up
    never_ready: bool = False  # of that: it ran, but never used the topics it was given
    not_run: bool = False  # skipped because it did not come up in an earlier scenario
    lidar_mount: LidarMount | None = None  # the mount the device was emulated with (serial links)
    # On a run-long device session: seconds between the previous scenario's last
    # revolution and this scenario's first judged one (the device kept streaming).
    gap_s: float | None = None
    node_start: str = ""  # how the node under test was started (by fork, as a command)
    # Ended at its first failed tick, the last record (RunSettings.stop_at_first_failure).
    stopped_early: bool = False

    @property
    def total_s(self) -> float:
        """What the scenario cost the run in wall time: start-up, the run, the stop."""
        return self.startup_s + self.wall_s + self.stop_s

    @property
    def ok(self) -> bool:
        return self.error is None and all(r.verdict.ok for r in self.records)

    @property
    def failed_ticks(self) -> list[TickRecord]:
        return [r for r in self.records if not r.verdict.ok]

    @property
    def broken(self) -> bool:
        """The run ended early and no answer was judged wrong before it (a verdict of ERROR).

        A node that died, a processing function that raised or a broken link is
        the break, not a wrong answer; a node that answers too late or not at all
        is judged on that (FAIL): its speed decides its verdict, not the run's.
        """
        return self.error is not None and all(
            r.answers.problem is not None and not r.answers.silent for r in self.failed_ticks
        )

    @property
    def first_failure(self) -> str | None:
        """The explanation read first: the run error or first failed tick, with the run's hint."""
        failed = self.failed_ticks
        if failed:
            seen = [r.answers.seen if r.answers.seen is not None else r.scan for r in self.records]
            verdicts = [r.verdict for r in self.records]
            hint = run_hint(verdicts, self.threshold, scans=seen, noise_sigma=self.noise_sigma)
            more = f" ({hint})" if hint else ""
            return f"{self.scenario}: {failed[0].verdict.explanation}{more}"
        if self.error is not None:
            return f"{self.scenario}: {self.error}"
        return None
