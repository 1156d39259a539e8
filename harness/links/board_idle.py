"""The idle stream's end, before a scenario's first revolution on a serial link.

The device streams from the session's start and between scenarios, so a node
(one started ahead has answered it for a whole scenario) hears scans before its
first tick. Before the first push the link lets the node answer what the stream
brought and forgets those answers, so none is taken for the first tick's
(``set_aside_answers_to_the_idle_stream`` is the last guard, by count). In lockstep
the stream stops and the driver falls quiet; in real time it never stops, so the
driver's scans are told apart by source time, as within a scenario."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from harness.judge.answers import Answers
from harness.nodes.quiescence import Quiescence

if TYPE_CHECKING:
    from collections.abc import Callable

    from harness.links.board_session import BoardSession
    from harness.links.node_exchange import NodeExchange

IDLE_ANSWER_S = 1.0  # before the first tick: for the node to answer the idle stream (each wait)
STREAM_QUIET_REVOLUTIONS = 3  # no board scan of the idle stream in this many: none is coming
IDLE_QUIET_MAX_S = 2.0  # longest wait for a lagging driver's last idle revolutions
# Longest wait for a node (that answered the idle stream) to answer its last revolutions
# and fall quiet: answered later, during the first tick, one would be taken for the first
# tick's answer (seen in CI: out_of_range's tick 0 answered with approach_wall's last).
IDLE_LAST_ANSWER_S = 3.0
IDLE_IN_FLIGHT_S = 0.03  # then for an answer already published to reach us


class IdleStreamEnd:
    """The board delivery's part that ends the session's idle stream before a scenario's
    first push; the delivery asks it whether the node may still owe idle answers."""

    def __init__(self, exchange: NodeExchange, on_over: Callable[[], None]) -> None:
        self.exchange = exchange
        self.on_over = on_over  # the stream is over: line damage acts from then on
        self.pushed = False  # the first push ends the session's idle stream
        # The node may still answer idle revolutions during the first tick (it lagged, or
        # answered none before the first tick, so how many it owes is not known).
        self.owed = False
        self.quiet_s = 0.0  # three revolutions at the first scan's rate

    def end(self, session: BoardSession, rate: float) -> None:
        """Before the first tick: wait (bounded) until the node answers an idle scan (so its
        subscription matched and the first scan reaches it), stop the idle stream, let the node
        answer the last scan it got, and forget those answers. A node silent when nothing is in
        range may answer none: each wait is bounded, and none is made when the board publishes
        no scan of the stream (a driver skipping sparse revolutions)."""
        obs = self.exchange.graph.observer
        assert obs is not None
        if self.pushed:
            return
        wait_for, grace = self.exchange.wait_for, self.exchange.grace
        began = time.perf_counter()

        def answering() -> bool:
            if obs.heard_since("status", 1):
                return True  # it answered a scan of the stream
            quiet = not any(h.kind == "scan" for h in obs.inbox)
            return quiet and time.perf_counter() - began > STREAM_QUIET_REVOLUTIONS / rate

        wait_for(answering, IDLE_ANSWER_S)
        answered = obs.heard_since("status", 1)
        self.over(session, rate)
        if session.mode == "realtime":
            self._caught_up(answered, STREAM_QUIET_REVOLUTIONS / rate)
            return
        # A driver that lags (a loaded machine: it clears its input buffer) still has
        # idle revolutions to publish: wait, bounded, until it has been quiet for three
        # revolutions, so the node answers them now, not during the first tick.
        quiet_s = STREAM_QUIET_REVOLUTIONS / rate

        def driver_quiet() -> bool:
            last = max((h.arrived for h in obs.inbox if h.kind == "scan"), default=began)
            return time.perf_counter() - last > quiet_s

        wait_for(driver_quiet, IDLE_QUIET_MAX_S)
        idle = [h.source_ns for h in obs.inbox if h.kind == "scan"]
        self.quiet_s, self.owed = quiet_s, bool(idle)
        pids = self._local_pids(session)
        if idle and pids:
            # The node and the board's software run here: wait (bounded) until every
            # thread of theirs sleeps, so none has a revolution left to answer.
            # A node that answered none of the stream may be asleep in its first
            # callback with the rest queued: asleep is not done for it.
            done = wait_for(Quiescence(pids), IDLE_LAST_ANSWER_S) is None
            self.owed = not (done and answered)
            wait_for(lambda: False, max(grace(), IDLE_IN_FLIGHT_S))
        elif idle and answered:
            # A node lagging on a loaded machine answers older scans after the last one
            # was published: wait (bounded) until it answered after the last idle scan and
            # then said nothing for three revolutions, so no idle answer is left to arrive
            # during the first tick.
            def answers_done() -> bool:
                return obs.heard_since("status", max(idle)) and self.statuses_quiet()

            self.owed = wait_for(answers_done, IDLE_LAST_ANSWER_S) == "timeout"
            wait_for(lambda: False, grace())  # its Bool, if any
        obs.drain()
        obs.inbox.clear()

    def _caught_up(self, answered: bool, quiet_s: float) -> None:
        """Real time: the device streams on, so nothing falls quiet before the first push. Wait
        (bounded) until the node answered after the newest driver scan (in order: no idle scan
        is left to answer during the first tick), then for its Bool; a node that answered none
        may still owe answers, which the first tick waits out."""
        obs = self.exchange.graph.observer
        assert obs is not None
        self.quiet_s = quiet_s
        if answered:

            def caught_up() -> bool:
                return obs.heard_since("status", obs.latest.get("scan", 0))

            self.owed = self.exchange.wait_for(caught_up, IDLE_LAST_ANSWER_S) == "timeout"
            self.exchange.wait_for(lambda: False, max(self.exchange.grace(), IDLE_IN_FLIGHT_S))
        else:
            self.owed = any(h.kind == "scan" for h in obs.inbox)
        obs.drain()
        obs.inbox.clear()

    def _local_pids(self, session: BoardSession) -> list[int]:
        """The node under test and the virtual board's processes (none for a physical
        board: its software runs elsewhere)."""
        if session.physical:
            return []
        processes = [p for _, p in session.processes]
        node = self.exchange.graph.process
        processes += [node] if node is not None else []
        return [p.node_pid for p in processes if p.node_pid is not None]

    def over(self, session: BoardSession, rate: float) -> None:
        """End the session's idle stream (this scenario's first push comes next); line
        damage acts from then on."""
        self.pushed = True
        self._after_idle_stream(session, rate)
        self.on_over()

    def _after_idle_stream(self, session: BoardSession, rate: float) -> None:
        """Lockstep: stop the session's idle stream and let the driver's scan of its last
        revolution come first, so it is never taken for this scenario's."""
        obs = self.exchange.graph.observer
        assert obs is not None
        since = session.end_idle()
        if since is None:
            return

        def idle_scan() -> bool:
            return any(h.kind == "scan" and h.source_ns >= since for h in obs.inbox)

        self.exchange.wait_for(idle_scan, max(self.exchange.options.scan_timeout, 1.0 / rate))

    def statuses_quiet(self) -> bool:
        """The node said nothing for three revolutions (it has at least answered once)."""
        obs = self.exchange.graph.observer
        assert obs is not None
        last = max((h.arrived for h in obs.inbox if h.kind == "status"), default=0.0)
        return time.perf_counter() - last > self.quiet_s


def set_aside_answers_to_the_idle_stream(answers: Answers, scans: int) -> None:
    """The first exchange after the idle stream: more statuses than driver scans in it means
    the earliest answer revolutions streamed before (a lagging driver publishes them late).
    The node answers in order: the last `scans` statuses (and the Bools nearest them) are
    this exchange's; the others are late answers of no tick."""
    statuses = sorted(answers.statuses, key=lambda r: r.source_ns)
    extra = len(statuses) - max(1, scans)
    if extra > 0:
        answers.keep_only(statuses[extra:])
