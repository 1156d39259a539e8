"""The idle stream's end, before a scenario's first revolution on a serial link.

A board's node hears scans before its scenario's first tick: the device
streams from the moment the run's session opens, and between scenarios it
keeps scanning the last world (``board_session.BoardSession.between``). A
node started ahead of its turn (``BoardLink.links_ahead``) has been
answering that stream, on topics of its own, for a whole scenario. Before
the first push the link makes sure the node is answering, lets it answer
what the stream brought, and forgets those answers, so none is taken for
the first tick's (``set_aside_answers_to_the_idle_stream`` is the last
guard, by count, in the first exchange).

In lockstep the idle stream stops (``BoardSession.end_idle``) and the
driver falls quiet; in real time the device never stops, so there is no
quiet to wait for: the driver's scans are told apart by source time, as
within a scenario.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from harness.judge.answers import Answers
from harness.nodes.quiescence import Quiescence

if TYPE_CHECKING:
    from collections.abc import Callable

    from harness.lidar.scan import Scan
    from harness.links.board_session import BoardSession
    from harness.ros.observer import Observer

IDLE_ANSWER_S = 1.0  # before the first tick: for the node to answer the idle stream (each wait)
STREAM_QUIET_REVOLUTIONS = 3  # no board scan of the idle stream in this many: none is coming
IDLE_QUIET_MAX_S = 2.0  # longest wait for a lagging driver's last idle revolutions
# Longest wait for a node (that answered the idle stream) to answer its last revolutions
# and fall quiet: answered later, during the first tick, one would be taken for the first
# tick's answer (seen in CI: out_of_range's tick 0 answered with approach_wall's last).
IDLE_LAST_ANSWER_S = 3.0
IDLE_IN_FLIGHT_S = 0.03  # then for an answer already published to reach us


class IdleStreamEnd:
    """BoardLink's part that ends the session's idle stream before a scenario's first push."""

    observer: Observer | None
    session: BoardSession | None
    server: Any
    physical: bool
    process: Any
    _pushed: bool
    _line_damage: Any
    _idle_quiet_s: float
    _idle_owed: bool

    # The link's own (Ros2Link's and BoardLink's).
    _wait_for: Callable[..., str | None]
    _grace: Callable[[], float]
    _rate: Callable[[Scan], float]
    options: Any

    def _end_idle_stream(self, scan: Scan) -> None:
        """Before the first tick: wait (bounded) until the node answers one of the idle
        stream's scans, so its subscription has matched the board's publisher and the
        first scan reaches it; stop the idle stream; let the node answer the last scan
        it made; forget those answers, so none is taken for the first tick's.

        Unlike the ros2 link's node, a board's has heard scans before the first tick:
        the device streams from the moment the session opens. A node silent when
        nothing is in range may answer none of an empty room's: each wait is bounded,
        and none is made when the board publishes no scan of the stream (a driver
        skipping sparse revolutions).
        """
        assert self.observer is not None
        if self._pushed:
            return
        obs = self.observer
        rate = self._rate(scan)
        began = time.perf_counter()

        def answering() -> bool:
            if obs.heard_since("status", 1):
                return True  # it answered a scan of the stream
            quiet = not any(h.kind == "scan" for h in obs.inbox)
            return quiet and time.perf_counter() - began > STREAM_QUIET_REVOLUTIONS / rate

        self._wait_for(answering, IDLE_ANSWER_S)
        answered = obs.heard_since("status", 1)
        self._idle_over(rate)
        if self.session is not None and self.session.mode == "realtime":
            self._caught_up(answered, STREAM_QUIET_REVOLUTIONS / rate)
            return
        # A driver that lags (a loaded machine: it clears its input buffer) still has
        # idle revolutions to publish: wait, bounded, until it has been quiet for three
        # revolutions, so the node answers them now, not during the first tick.
        quiet_s = STREAM_QUIET_REVOLUTIONS / rate

        def driver_quiet() -> bool:
            last = max((h.arrived for h in obs.inbox if h.kind == "scan"), default=began)
            return time.perf_counter() - last > quiet_s

        self._wait_for(driver_quiet, IDLE_QUIET_MAX_S)
        idle = [h.source_ns for h in obs.inbox if h.kind == "scan"]
        self._idle_quiet_s, self._idle_owed = quiet_s, bool(idle)
        pids = self._local_pids()
        if idle and pids:
            # The node and the board's software run here: wait (bounded) until every
            # thread of theirs sleeps, so none has a revolution left to answer.
            # A node that answered none of the stream may be asleep in its first
            # callback with the rest queued: asleep is not done for it.
            done = self._wait_for(Quiescence(pids), IDLE_LAST_ANSWER_S) is None
            self._idle_owed = not (done and answered)
            self._wait_for(lambda: False, max(self._grace(), IDLE_IN_FLIGHT_S))
        elif idle and answered:
            # A node lagging on a loaded machine answers older scans after the last one
            # was published: wait (bounded) until it answered after the last idle scan and
            # then said nothing for three revolutions, so no idle answer is left to arrive
            # during the first tick.
            def answers_done() -> bool:
                return obs.heard_since("status", max(idle)) and self._statuses_quiet()

            self._idle_owed = self._wait_for(answers_done, IDLE_LAST_ANSWER_S) == "timeout"
            self._wait_for(lambda: False, self._grace())  # its Bool, if any
        obs.drain()
        obs.inbox.clear()

    def _caught_up(self, answered: bool, quiet_s: float) -> None:
        """Real time: the device streams on (as a real one does), so neither the driver
        nor the node falls quiet before the first push, and the driver's scans are told
        apart by source time, as within a scenario. Wait (bounded) until the node has
        answered after the newest scan the driver published (it answers in order: no
        older idle scan is left to answer during the first tick), then for its Bool.

        A node that answered none of the stream (silent when nothing is in range)
        may owe answers still: the first tick waits for it to fall quiet.
        """
        assert self.observer is not None
        obs = self.observer
        self._idle_quiet_s = quiet_s
        if answered:

            def caught_up() -> bool:
                return obs.heard_since("status", obs.latest.get("scan", 0))

            self._idle_owed = self._wait_for(caught_up, IDLE_LAST_ANSWER_S) == "timeout"
            self._wait_for(lambda: False, max(self._grace(), IDLE_IN_FLIGHT_S))
        else:
            self._idle_owed = any(h.kind == "scan" for h in obs.inbox)
        obs.drain()
        obs.inbox.clear()

    def _local_pids(self) -> list[int]:
        """The node under test and the virtual board's processes (none for a physical
        board: its software runs elsewhere)."""
        if self.physical:
            return []
        processes = [p for _, p in self.session.processes] if self.session is not None else []
        processes += [self.process] if self.process is not None else []
        return [p.node_pid for p in processes if p.node_pid is not None]

    def _idle_over(self, rate: float) -> None:
        """End the session's idle stream (this scenario's first push comes next); line
        damage acts from then on."""
        assert self.server is not None
        self._pushed = True
        self._after_idle_stream(rate)
        if self._line_damage is not None:
            self.server.damage = self._line_damage

    def _after_idle_stream(self, rate: float) -> None:
        """Lockstep: stop the session's idle stream and let the driver's scan of its last
        revolution come first, so it is never taken for this scenario's."""
        assert self.session is not None and self.observer is not None
        since = self.session.end_idle()
        if since is None:
            return
        obs = self.observer

        def idle_scan() -> bool:
            return any(h.kind == "scan" and h.source_ns >= since for h in obs.inbox)

        self._wait_for(idle_scan, max(self.options.scan_timeout, 1.0 / rate))

    def _statuses_quiet(self) -> bool:
        """The node said nothing for three revolutions (it has at least answered once)."""
        assert self.observer is not None
        last = max((h.arrived for h in self.observer.inbox if h.kind == "status"), default=0.0)
        return time.perf_counter() - last > self._idle_quiet_s


def set_aside_answers_to_the_idle_stream(answers: Answers, scans: int) -> None:
    """The first exchange after the idle stream: more statuses than the driver published
    scans in it means the earliest answer revolutions streamed before (a driver lagging
    on a loaded machine publishes them late, after the harness stopped waiting for
    them). The node answers in order, so the last `scans` statuses (and the Bools nearest
    to them) are this exchange's; the others are kept as late answers of no tick."""
    statuses = sorted(answers.statuses, key=lambda r: r.source_ns)
    extra = len(statuses) - max(1, scans)
    if extra > 0:
        answers.keep_only(statuses[extra:])
