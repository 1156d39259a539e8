"""The lockstep loop: deliver each frame's scan through a link, collect, judge, record.

Simulated runs and replayed recordings share it, so both are judged the
same way. Lockstep by default: scan k+1 is sent only after scan k's
answers arrived or its deadline passed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

from harness.errors import ConfigError, Interrupted, LinkError
from harness.faults.link import NO_LINK_FAULTS, Delivery, LineDamage, LinkFaults, plan_deliveries
from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan
from harness.links.base import Link
from harness.links.kinds import either, serial_links


@dataclass(frozen=True)
class Frame:
    """One scan to deliver, and where the robot was when it was taken."""

    tick: int
    t: float  # seconds since the start of the run (simulated or recorded)
    x: float
    y: float
    yaw: float
    scan: Scan


def check_link_faults(faults: LinkFaults, link: Link) -> None:
    """Refuse link faults this link cannot carry (before any scan is sent)."""
    if faults.on_line and not link.serial_line:
        kinds = ", ".join(f.kind for f in faults.items if f.kind.startswith("line_"))
        raise ConfigError(
            f"faults {kinds}: need a serial link ({either(serial_links())}), not {link.name!r}"
        )
    if faults.stale_stamps and link.serial_line:
        raise ConfigError(
            f"faults stale_stamps: on the {link.name!r} link the board's driver stamps the "
            "scans, not the harness"
        )


def judge_frames(
    frames: Iterable[Frame],
    link: Link,
    oracle: Oracle,
    result: RunResult,
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
    link_faults: LinkFaults = NO_LINK_FAULTS,
    diagnose: bool = True,
    stop_at_first_failure: bool = False,
) -> RunResult:
    """Deliver each frame's scan through an opened `link`; judge and record every tick.

    `link_faults` decide how each scan travels, and the oracle is told (a
    dropped scan expects no answer, a late one is timed from when it went out).
    With `diagnose` the link's diagnostics end the run (stopping its node);
    without, the link stays usable. `stop_at_first_failure` ends the run at
    its first failed tick (`result.stopped_early`).
    """
    # A tick waits in `pending` until the next scan's exchange is over:
    # answers to scan k that arrive after scan k+1 was sent (a Bool published
    # after the String, a second String) still count for scan k. Its answers
    # then complete, it moves to `ready` and is judged while the node works
    # on the scan after (the script never depends on verdicts, so lockstep is
    # unchanged and the oracle's time is off the round trip).
    pending: list[tuple[Frame, Answers, Delivery]] = []  # frames carry the scans as sent
    ready: list[tuple[Frame, Answers, Delivery]] = []

    def judge(frame: Frame, answers: Answers, delivery: Delivery) -> None:
        if result.stopped_early:  # the failed tick is the run's last
            return
        # Judge against what the node saw: over a serial link that is the
        # board driver's scan, quantised and re-binned, not ours.
        seen = answers.seen if answers.seen is not None else frame.scan
        verdict = oracle.judge(frame.tick, frame.t, seen, answers, delivery)
        # Judged whole; kept clipped (lengths noted), so a flood cannot bloat the reports.
        taken = (frame.tick, frame.t, frame.x, frame.y, frame.yaw, frame.scan)
        record = TickRecord(*taken, answers.clipped(), verdict.clipped(), delivery)
        result.records.append(record)
        if on_tick is not None:
            on_tick(record)
        if stop_at_first_failure and not verdict.ok:
            result.stopped_early = True

    def judge_ready() -> None:
        for held in ready:
            judge(*held)
        ready.clear()

    def complete_pending(late: list[Received]) -> list[Received]:
        """Give the pending ticks their late answers; they are ready to judge."""
        for frame, answers, delivery in pending:
            if delivery.delivered:
                late = answers.take_late(late, frame.tick)
        ready.extend(pending)
        pending.clear()
        return late

    started = False
    planned = iter(plan_deliveries(frames, link_faults, result.seed))
    current: Frame | None = None  # the frame being delivered, for an interruption's message
    try:
        upcoming = next(planned, None)
        while upcoming is not None:
            frame, delivery = upcoming
            current = frame
            if not delivery.delivered:
                pending.append((frame, Answers(), delivery))
                upcoming = next(planned, None)
                continue
            scan = frame.scan
            if delivery.stamp_age_s:
                scan = replace(scan, stamp=max(0.0, frame.t - delivery.stamp_age_s))
            try:
                if delivery.delay_s:
                    link.hold(delivery.delay_s)
                if started:
                    link.send(scan, frame.tick, clock=frame.t)
                else:
                    if link_faults.on_line:  # from the first scan on (each copy alike)
                        link.damage_line(LineDamage(link_faults, result.seed))
                    _send_first(link, frame, scan, delivery)
                    started = True
                # While the node works on this scan, judge the ticks that are
                # complete and simulate the next one.
                judge_ready()
                if result.stopped_early:  # the scan just sent is never collected
                    break
                upcoming = next(planned, None)
                answers = link.collect(scan, frame.tick, may_be_ignored=delivery.may_be_ignored)
            except LinkError as err:  # the line or graph broke: end here, keep what we have
                result.error = f"t={frame.t:.2f} s tick {frame.tick}: {err}"
                break
            answers.late = complete_pending(answers.late)
            pending.append((replace(frame, scan=scan), answers, delivery))
            if answers.problem is not None:  # the node died or went silent: nothing more to judge
                result.error = f"t={frame.t:.2f} s tick {frame.tick}: {answers.problem}"
                break
            if stop_at_first_failure and _fails_alone(answers, delivery):
                complete_pending([])  # judged now: later answers cannot make it pass
                judge_ready()
                if result.stopped_early:
                    break
        if not result.stopped_early:
            complete_pending(link.settle())  # ready ticks stay ahead of the pending ones
            judge_ready()
    except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM: keep what was judged, say where
        judge_ready()  # complete ticks only; those still waiting for answers are not judged
        raise _interrupted(err, result, current) from None
    if diagnose:
        result.notes = link.notices()  # before the diagnostics, which stop the node
        result.diagnostics = link.diagnostics()
    return result


def _fails_alone(answers: Answers, delivery: Delivery) -> bool:
    """The tick fails whatever comes after: its scan went out, no status came by its
    deadline, and an answer to a scan whose deadline passed stays late (take_late)."""
    return (
        answers.timed_out
        and not answers.statuses
        and delivery.delivered
        and not delivery.may_be_ignored
        and answers.lost is None
    )


def _send_first(link: Link, frame: Frame, scan: Scan, delivery: Delivery) -> None:
    """The run's first scan: sent (resent until answered, where a link may lose it) and
    judged, so the node's first answer is judged. One a careful node may ignore (a
    stale stamp) cannot show that the node is up: a warm-up exchange of the scan as
    taken goes first, its answers not judged."""
    if delivery.may_be_ignored:
        link.warm_up(frame.scan)
        link.send(scan, frame.tick, clock=frame.t)
    else:
        link.send_first(scan, frame.tick, clock=frame.t)


def _interrupted(err: KeyboardInterrupt, result: RunResult, frame: Frame | None) -> Interrupted:
    """The run's partial result, ended by the signal, for the caller to report."""
    stop = Interrupted.of(err)
    where = f" at t={frame.t:.2f} s tick {frame.tick}" if frame is not None else ""
    count = len(result.records)
    ticks = f"{count} tick{'' if count == 1 else 's'} judged"
    result.error = f"interrupted by {stop.name}{where} ({ticks})"
    return Interrupted(stop.signum, [result])
