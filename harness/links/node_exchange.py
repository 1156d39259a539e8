"""One node exchange: a scan goes out, the node's answers to it are waited for and paired.

Lockstep: deliver scan k, then spin until its status arrives or the per-scan deadline
(counted from the send) passes. Answers are matched to scans by the DDS source
timestamp the node's publisher put on them, so a message published before scan k went
out is never scan k's answer. Whether the node publishes its Bool before or after its
String is learned as the run goes: Bool first costs no wait; otherwise a short grace
(a few ms, never the deadline) lets the same callback's Bool arrive.

The run's first scan (``send_first``) is resent until answered, since a scan or answer
sent while the graph still matches may be lost, and that answer is judged: a node that
publishes only on change has nothing to hold back at tick 0. How a scan reaches the
node is the delivery's (``ScanDelivery``: published, or pushed to a board's device)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Protocol

from harness.errors import LinkError
from harness.judge.answers import Answers, Received
from harness.links import start_explanations
from harness.links.bounds import (
    BOOL_DISCOVERY_S,
    FIRST_RETRY_MAX_S,
    MIN_GRACE_S,
    POLL_S,
    WARM_UP_RETRY_S,
    catch_up_s,
)
from harness.links.topic_advice import BOOL_TYPE
from harness.links.watchdogs import FloodWatch, SilenceWatch, Topics, strangers_problem

if TYPE_CHECKING:
    from harness.lidar.scan import Scan
    from harness.links.base import LinkOptions
    from harness.links.node_graph import NodeGraph
    from harness.ros.observer import Heard


class ScanDelivery(Protocol):
    """How scans reach the node, plugged into a ``NodeExchange``; the bodies here are those
    of a delivery with nothing more to do (publishing over ROS 2)."""

    # A copy of the first scan the node did not answer in time may still be queued in
    # it (a slow first callback), to be answered before the next scan; its first copy's
    # answer is then the tick's.
    copies_queue: bool

    def deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        """Put the scan in front of the node; return its send time (system-clock ns)."""
        ...

    def reached_node(self) -> bool:
        """Did the scan just delivered reach the node? (A board may drop one.)"""
        return True

    def answered(self) -> bool:
        """Has the status answering the scan just sent arrived?"""
        ...

    def copy(self, n: int) -> None:
        """Copy `n` (0 first) of the first scan is about to go out."""

    def before_first(self, scan: Scan) -> None:
        """Before the run's first scan goes out (its first copy)."""

    def after_first(self) -> None:
        """The first scan's copies are out and answered (or given up on)."""

    def after_warm_up(self) -> None:
        """The warm-up exchange is over."""

    def unanswerable(self) -> Answers | None:
        """This tick's answers when there is nothing to wait for (a lost revolution)."""
        return None

    def settle_answers(self) -> None:
        """Once the answers are in, anything else to wait (briefly) for."""

    def sorted(self, answers: Answers, heard: list[Heard]) -> None:
        """The exchange has split what arrived (`heard`) into answers and late ones."""

    def collected(self, answers: Answers) -> Answers:
        """This tick's answers, as the delivery pairs them."""
        return answers

    def settled(self) -> None:
        """What `settle` heard is in the inbox, before its answers get their ticks."""


class NodeExchange:
    """The lockstep (or real-time) exchange of scans and answers with one node."""

    def __init__(
        self, graph: NodeGraph, make_delivery: Callable[[NodeExchange], ScanDelivery]
    ) -> None:
        self.graph = graph
        self.sent_ns: int = 0
        self._sent_at: float = 0.0
        # (tick, sent_ns) of recent scans; tick None: a scan no tick sent (a board's repeat)
        self.sends: list[tuple[int | None, int]] = []
        self._started_at: float | None = None  # real time: when scan 0 went out
        self._delay = 0.0  # seconds the next scan is held (link fault)
        self._bool_first_seen = 0
        self._bool_after_gap = 0.0  # longest String -> Bool gap seen, seconds
        o = graph.options
        topics = Topics(graph.command.description, o.scan_topic, o.status_topic, o.warning_topic)
        self._silence = SilenceWatch(topics, o.scan_timeout)
        self._flood = FloodWatch(o.status_topic, o.warning_topic)
        self.copies = 1  # copies of the scan just sent (the first one is resent until answered)
        self.warmed_up = False
        self._first_silence: str | None = None  # why the first scan went unanswered
        self._first_waited = 0.0  # seconds its copies were given
        self.wait_for = graph.wait_for  # the one bounded wait (``NodeGraph.wait_for``)
        self.delivery = make_delivery(self)

    @property
    def options(self) -> LinkOptions:
        return self.graph.options

    def send_first(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        """Send the run's first scan until a copy is answered (bounded by the ready timeout);
        `collect` takes that answer as this tick's.

        Ready means our endpoints matched the node's, not yet its ours, so a copy or its
        answer may be lost: resent after WARM_UP_RETRY_S, doubling up to FIRST_RETRY_MAX_S,
        so a node slow on its first scan is not sent many. A node that dies meanwhile is
        left for `collect` to report, at this tick."""
        graph = self.graph
        assert graph.observer is not None
        obs, opts = graph.observer, self.options
        self.delivery.before_first(scan)
        self._await_bool_writer()  # its first Bool must reach us
        bool_matched = obs.warning_publishers() > 0
        self._flood.restart(obs.heard["status"], obs.heard["warning"])
        first_at = time.perf_counter()
        deadline = first_at + opts.ready_timeout
        first_ns = time.time_ns()
        copies, retry = 0, WARM_UP_RETRY_S
        while True:
            if copies:  # what answers an earlier copy answers no tick
                self.sends[-1] = (None, self.sends[-1][1])
            self._started_at = None  # real time counts from the copy that is answered
            self.delivery.copy(copies)
            self.send(scan, tick, clock=clock)
            copies += 1
            if not self.delivery.reached_node():
                break  # no answer can come (a board that published no scan of it)
            answered = self.delivery.answered
            outcome = self.wait_for(answered, min(retry, deadline - time.perf_counter()))
            retry = min(2 * retry, FIRST_RETRY_MAX_S)
            if outcome != "timeout":
                break  # answered; or the node is gone, which collect reports at this tick
            graph.check_types()
            if time.perf_counter() >= deadline:  # judged at this tick (collect): silent
                self._first_silence = start_explanations.never_answered(
                    graph.command.description, opts, scan, copies
                )
                self._first_waited = time.perf_counter() - first_at
                break
        self.copies = copies
        if self._first_silence is None and not bool_matched:
            self._await_first_bool(first_ns)
        if copies > 1 and self.delivery.copies_queue and self._first_silence is None:
            # A node slow on its first scan has the other copies queued: let it answer
            # them (each about as long as the first took) before the next scan goes out,
            # or their answers would be taken for that scan's.
            took = time.perf_counter() - first_at
            self.wait_for(
                lambda: obs.statuses_since(first_ns) >= copies,
                min(max(WARM_UP_RETRY_S, copies * took), opts.ready_timeout),
            )
        self._name_wrong_types()
        if graph.node_gone() is None:
            graph.check_types()
        self.warmed_up = True
        self.delivery.after_first()

    def _name_wrong_types(self) -> None:
        """Give discovery a moment (bounded) to tie a wrongly typed publisher to its node,
        so the error names it."""
        obs = self.graph.observer
        assert obs is not None
        self.wait_for(
            lambda: not obs.wrong_types() or bool(obs.wrong_types(named_only=True)), WARM_UP_RETRY_S
        )

    def _await_bool_writer(self) -> None:
        """Before the first scan: our Bool reader matched to the node's Bool writer, or its
        first Bool would be dropped as a stranger's. Writers and readers are announced in no
        common order, so ready can come before the Bool writer is known: wait for the match
        while the graph shows one, and BOOL_DISCOVERY_S for one to show at all."""
        assert self.graph.observer is not None
        obs, topic = self.graph.observer, self.options.warning_topic
        if obs.warning_publishers() > 0:
            return
        if obs.node.count_publishers(topic) == 0:
            # As long as the graph took to show the node ready (a busy machine's
            # discovery is slower), and BOOL_DISCOVERY_S at least.
            bound = max(BOOL_DISCOVERY_S, self.graph.ready_took)
            self.wait_for(lambda: obs.node.count_publishers(topic) > 0, bound)
        if obs.node.count_publishers(topic) > 0:
            self.wait_for(lambda: obs.warning_publishers() > 0, WARM_UP_RETRY_S)

    def _await_first_bool(self, first_ns: int) -> None:
        """The first scan was answered without a Bool while our reader matched no Bool writer:
        where the graph shows one only now (slow discovery), Fast DDS repairs the Bool it
        published before the match. Wait for it, bounded by the deadline, so tick 0 is judged
        on what the node published, not on discovery's speed."""
        assert self.graph.observer is not None
        obs, topic = self.graph.observer, self.options.warning_topic
        if obs.heard_since("warning", first_ns):
            return
        bool_writers = [
            info
            for info in obs.node.get_publishers_info_by_topic(topic)
            if info.topic_type == BOOL_TYPE
        ]
        if obs.warning_publishers() == 0 and not bool_writers:
            return  # no Bool writer in sight, even now (another type is named elsewhere)
        self.wait_for(lambda: obs.heard_since("warning", first_ns), self.options.scan_timeout)

    def warm_up(self, scan: Scan) -> None:
        """Exchange a scan until its answer reaches us, then forget it (the benchmarks' untimed
        first exchange; a run whose first scan a node may ignore). Our subscriptions matching
        does not mean the node's publishers matched us, so its first answers could be lost."""
        graph = self.graph
        assert graph.observer is not None
        obs, opts = graph.observer, self.options
        deadline = time.perf_counter() + opts.ready_timeout
        copies = 0
        while True:
            sent_ns = self.delivery.deliver(scan, -1)
            copies += 1
            if not self.delivery.reached_node():
                break  # no answer can come (a board that published no scan of it)

            def answered(since: int = sent_ns) -> bool:
                return obs.heard_since("status", since)

            outcome = self.wait_for(answered, min(WARM_UP_RETRY_S, deadline - time.perf_counter()))
            if outcome is None:
                break
            if outcome != "timeout":  # it names the node (or the driver, or the line) already
                raise LinkError(graph.node_gone("while warming up") or outcome)
            # Ready may have counted a publisher the node has since replaced (a reliable
            # one swapped for best-effort, say): what can never be heard is said now.
            graph.check_types()
            if time.perf_counter() >= deadline:
                raise LinkError(
                    start_explanations.never_answered(graph.command.description, opts, scan, copies)
                )
        if obs.node.count_publishers(opts.warning_topic) > 0:
            self.wait_for(lambda: obs.warning_publishers() > 0, WARM_UP_RETRY_S)
        self._name_wrong_types()  # by now the node's other publishers are known too
        graph.check_types()
        self.wait_for(lambda: False, self.grace())  # the answer's Bool, if any
        obs.drain()
        obs.inbox.clear()
        self._flood.restart(obs.heard["status"], obs.heard["warning"])
        self.warmed_up = True
        self.delivery.after_warm_up()

    # -- lockstep ---------------------------------------------------------
    def send(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        assert self.graph.observer is not None, "open() the link first"
        now = scan.stamp if clock is None else clock
        if self.options.realtime:
            self._pace(now)
        if self._delay:  # a delayed scan: its time (paced or not) plus the delay
            delay, self._delay = self._delay, 0.0
            self.wait_for(lambda: False, delay)
        self.sent_ns = self.delivery.deliver(scan, tick, clock=now)
        self._sent_at = time.perf_counter()
        self.sends = [*self.sends[-7:], (tick, self.sent_ns)]

    def _pace(self, clock: float) -> None:
        """Real time: a scan taken at `clock` goes out that long after the first one,
        hearing answers meanwhile (a drifting rate keeps its own spacing)."""
        assert self.graph.observer is not None
        if self._started_at is None:
            self._started_at = time.perf_counter() - clock
            return
        due = self._started_at + clock
        while (left := due - time.perf_counter()) > 0:
            self.graph.observer.spin(min(POLL_S, left))

    def hold(self, seconds: float) -> None:
        """Delay the next scan; the node is heard while the delay passes (in `send`)."""
        self._delay = seconds

    def _deadline(self, scan: Scan) -> float:
        """Seconds a scan's answers may take: in real time, also before the next scan."""
        if self.options.realtime:
            return min(self.options.scan_timeout, scan.scan_time)
        return self.options.scan_timeout

    def grace(self) -> float:
        """How long after a status its Bool is waited for (as this node's order says)."""
        if self._bool_first_seen and not self._bool_after_gap:
            return 0.0
        return min(max(MIN_GRACE_S, 4 * self._bool_after_gap), self.options.scan_timeout)

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        """Wait (bounded) for the answers to the scan just sent; pair them with it."""
        early = self.delivery.unanswerable()
        if early is not None:
            return early
        graph = self.graph
        assert graph.observer is not None
        obs = graph.observer
        answers = Answers()

        def mine(h: Heard) -> bool:
            return h.source_ns >= self.sent_ns

        status_in = self.delivery.answered

        def warning_in() -> bool:
            return obs.heard_since("warning", self.sent_ns)

        timeout = self._deadline(scan)
        silence, self._first_silence = self._first_silence, None
        if silence is not None:  # the first scan's copies went unanswered: nothing to wait for
            outcome: str | None = "timeout"
        else:
            outcome = self.wait_for(status_in, self._sent_at + timeout - time.perf_counter())
        if outcome == "timeout":
            answers.timed_out = True
            outcome = None
            opts = self.options
            if silence is None and not (opts.realtime or may_be_ignored or opts.late_ends_run):
                # The node is behind. Let it catch up before the next scan, or its
                # answer to this scan would be taken for an answer to the next one.
                outcome = self.wait_for(status_in, catch_up_s(timeout))
                outcome = None if outcome == "timeout" else outcome
        answers.problem = outcome
        if outcome is not None and graph.node_exited():
            answers.problem = f"node {graph.command.description} {graph.crash_summary()}"
            answers.crashed = True
        if status_in():
            self.wait_for(warning_in, self.grace())
            self.delivery.settle_answers()
            obs.drain()
        self._sort(answers, obs.inbox, mine)
        self.delivery.sorted(answers, obs.inbox)
        obs.inbox.clear()
        if len(answers.statuses) > 1 and answers.problem is None:
            answers.problem = self._strangers()
        if self.copies > 1 and self.delivery.copies_queue:
            # The first scan went more than once: keep the first copy's answer (the node
            # saw nothing before it; the later ones become late answers of no tick).
            answers.first_answer_only()
        self.copies = 1
        if answers.timed_out:  # whatever came after the deadline is late, not an answer
            answers.late += [
                Received(r.value, r.after, tick) for r in (*answers.statuses, *answers.warnings)
            ]
            answers.statuses, answers.warnings = [], []
            answers.waited = timeout if silence is None else self._first_waited
        else:
            answers.waited = time.perf_counter() - self._sent_at
        if silence is not None and answers.problem is None:
            answers.problem, answers.silent = silence, True
        elif not (may_be_ignored and answers.timed_out):  # a node may skip such a scan
            self._silence.see(answers, tick, empty=not scan.valid_mask().any())
        heard = obs.heard
        self._flood.see(
            answers, heard["status"], heard["warning"], time.perf_counter() - self._sent_at
        )
        return self.delivery.collected(answers)

    def _strangers(self) -> str | None:
        assert self.graph.observer is not None
        domain = self.graph.domain
        domain_id = domain.domain_id if domain is not None else None
        return strangers_problem(self.graph.observer.strangers(), domain_id)

    def _sort(self, answers: Answers, heard: Iterable[Heard], mine) -> None:
        """Split what arrived into this scan's answers and late ones; learn the Bool order."""
        first_status = next((h for h in heard if h.kind == "status" and mine(h)), None)
        string_first = self._bool_after_gap > 0 and not self._bool_first_seen
        for h in heard:
            if h.kind == "scan":
                continue  # a driver's scan (serial links): not an answer
            item = Received(h.value, h.arrived - self._sent_at, source_ns=h.source_ns)
            if not mine(h):
                answers.late.append(Received(h.value, item.after, self.tick_of(h.source_ns)))
            elif h.kind == "status":
                answers.statuses.append(item)
            elif (
                string_first
                and first_status is not None
                and h.source_ns < first_status.source_ns
                and len(self.sends) > 1
            ):
                # A node that publishes its Bool after its String, caught
                # between the two (a busy thread holding its GIL) until this
                # scan had gone out: the Bool answers the scan before.
                answers.late.append(Received(h.value, item.after, self.sends[-2][0]))
            else:
                answers.warnings.append(item)
                if first_status is not None:
                    if h.source_ns <= first_status.source_ns:
                        self._bool_first_seen += 1
                    else:
                        gap = (h.source_ns - first_status.source_ns) / 1e9
                        self._bool_after_gap = max(self._bool_after_gap, gap, 1e-4)

    def tick_of(self, source_ns: int) -> int | None:
        """The last scan sent before the node published this message."""
        earlier = [tick for tick, sent in self.sends if sent <= source_ns]
        return earlier[-1] if earlier else None

    def settle(self) -> list[Received]:
        """Answers to the last scan that come after its status (e.g. a trailing Bool)."""
        obs = self.graph.observer
        if obs is None:
            return []
        end = time.perf_counter() + self.grace()
        while time.perf_counter() < end:
            obs.spin(end - time.perf_counter())
        obs.drain()
        self.delivery.settled()
        late = [
            Received(h.value, h.arrived - self._sent_at, self.tick_of(h.source_ns))
            for h in obs.inbox
            if h.kind != "scan"
        ]
        obs.inbox.clear()
        return late
