"""The ros2 link: a real node in its own process, over a real DDS graph.

Lockstep: publish scan k, then spin until the node's status for it arrives
or the per-scan deadline passes. Answers are matched to scans by the DDS
source timestamp the node's publisher put on them, so a message published
before scan k was sent can never be taken as an answer to scan k.

Whether a node publishes its Bool before or after its String is learned as
the run goes: a node seen to publish the Bool first costs no wait at all; for
others a short grace after the String lets the Bool of the same callback
arrive (bounded, a few ms; never a fixed per-scan wait of the deadline).

While the node comes up, the harness publishes /clock (time 0), so a node
that waits for a clock before it subscribes to the scans can start; the
first scan's /clock is time 0 as well.

The node's first scan is the run's first tick (``send_first``): resent until
it is answered, since a scan or an answer sent while the graph is still
matching may be lost, and its answer judged like any other. So the first
answer a node gives is judged, and a node that publishes only when its
status changes has nothing to hold back at tick 0.

A hostile node gets a verdict, not a hang (docs/hostile_nodes.md): a wrong
message type on a topic is named from the ROS graph at once, a flood of
messages ends the run, and when the run is over the node is stopped (and
every process it started) before the diagnostics are written, so they say
if it had to be killed.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

from harness.errors import ConfigError, LinkError, NeverReady
from harness.judge.answers import Answers, Received
from harness.links import start_explanations
from harness.links.base import Link, LinkOptions, register
from harness.links.node_notes import WiringNotes, output_notes
from harness.links.node_start import harness_observer, launch_check, node_command, node_parameters
from harness.links.topic_advice import (
    BOOL_TYPE,
    ElsewhereWatch,
    topic_hints,
)
from harness.links.watchdogs import FloodWatch, SilenceWatch, Topics, strangers_problem
from harness.nodes.command import (
    node_arguments,
)
from harness.nodes.process import NodeProcess, prepare_start, start_would_wait
from harness.ros.domain import (
    DomainReservation,
    NoFreeDomain,
    discovery_environment,
    reserve_domain,
)

if TYPE_CHECKING:  # numpy and rclpy are imported when the first link starts, after its node
    from harness.launch_files.run_check import LaunchCheck  # read for --package, --launch
    from harness.lidar.scan import Scan
    from harness.ros.observer import Heard, Observer

POLL_S = 0.05  # longest single spin; liveness of the node is checked this often
READY_POLL_S = 0.005  # spins while waiting for the graph, whose changes wake no spin
MIN_GRACE_S = 0.002  # wait for a Bool after the String while the order is unknown
WARM_UP_RETRY_S = 0.5  # resend the first scan (or a warm-up scan) this often until answered
BOOL_DISCOVERY_S = 0.25  # before the first scan: for a Bool writer the graph does not show yet
FIRST_RETRY_MAX_S = 2.0  # the first scan's resends back off up to this interval
# Once ready, for discovery to name the node reading the scans (Observer.scan_readers_named);
# a participant that never names itself (no ROS node) is sent its first scan after this.
NAMED_WAIT_S = 0.5
CATCH_UP_S = 2.0  # after a missed deadline, wait this long (at least) for the late answer


@register("ros2")
class Ros2Link(Link):
    """Drive a ROS 2 node process through its scan topic; watch status and warning."""

    publishes_scans = True  # the harness publishes /scan (a board link listens instead)
    # A copy of the first scan the node did not answer in time may still be queued in
    # it (a slow first callback), to be answered before the next scan.
    copies_queue = True
    sets_node_topics = True
    starts_ahead = True  # each link has its own domain, so several can be up at once

    def __init__(self, options: LinkOptions, session: LaunchCheck | None = None) -> None:
        super().__init__(options)
        self.command = node_command(options)  # resolve now: bad input exits 2 early
        self._wiring = WiringNotes(options, session)  # the run's launch files, if any
        self.process: NodeProcess | None = None
        self.observer: Observer | None = None
        self.domain: DomainReservation | None = None
        self._sent_ns: int = 0
        self._sent_at: float = 0.0
        # (tick, sent_ns) of recent scans; tick None: a scan no tick sent (a board's repeat)
        self._sends: list[tuple[int | None, int]] = []
        self._started_at: float | None = None  # real time: when scan 0 went out
        self._delay = 0.0  # seconds the next scan is held (link fault)
        self._bool_first_seen = 0
        self._bool_after_gap = 0.0  # longest String -> Bool gap seen, seconds
        o = options
        topics = Topics(self.command.description, o.scan_topic, o.status_topic, o.warning_topic)
        self._silence = SilenceWatch(topics, options.scan_timeout)
        self._flood = FloodWatch(options.status_topic, options.warning_topic)
        self._copies = 1  # copies of the scan just sent (the first one is resent until answered)
        self._alive_until = 0.0  # perf_counter until which the node counts as running
        self._warmed_up = False
        self.startup_s = 0.0
        self._started = False
        self._start_error: Exception | None = None
        self._no_domain: NoFreeDomain | None = None  # why start() could not start it yet
        self._first_silence: str | None = None  # why the first scan went unanswered
        self._first_waited = 0.0  # seconds its copies were given
        self._ready_took = 0.0  # seconds `open` waited for the graph to show the node ready
        self._gave_up_early_s: float | None = None  # readiness abandoned early, after this

    # -- life cycle -------------------------------------------------------
    @classmethod
    def run_session(
        cls, options: LinkOptions
    ) -> contextlib.AbstractContextManager[LaunchCheck | None]:
        """The package's launch files, read once for the run (harness.launch_files)."""
        return contextlib.nullcontext(launch_check(options))

    @classmethod
    def prepare(cls, options: LinkOptions) -> None:
        """Start the fork server of the node, if it has one (its imports take a while)."""
        with contextlib.suppress(ConfigError):  # a bad node is reported where it is used
            prepare_start(node_command(options))

    def start(self) -> None:
        """Reserve a domain, start the node and the harness's own ROS node; do not wait.

        A suite starts the next scenarios' links this way while one runs
        (each in its own domain); `open` then waits for readiness.
        A failure to start is kept and raised by `open`, so a link started
        ahead reports it when its own scenario comes, as if started then.
        With no domain free (this machine's other runs hold them all), the
        link is left unstarted: `open` tries again when its scenario comes.
        """
        if self._started:
            return
        opts = self.options
        try:
            self.domain = reserve_domain(opts.domain_id)
        except NoFreeDomain as err:
            self._no_domain = err
            return
        except Exception as err:  # raised again by open()
            self._started, self._start_error = True, err
            return
        self._started = True
        try:
            env = {
                "ROS_DOMAIN_ID": str(self.domain.domain_id),
                **discovery_environment(network=opts.ros_network),
            }
            if start_would_wait(self.command):  # build our side while its fork server imports
                self.observer = self._make_observer(self.domain.domain_id)
                self._start_processes(env)
            else:  # the node first: it takes longest to come up
                self._start_processes(env)
                self.observer = self._make_observer(self.domain.domain_id)
        except Exception as err:  # raised again by open()
            self._start_error = err

    def open(self) -> None:
        """Start (unless started ahead) and wait, bounded, until the node is ready."""
        started = time.perf_counter()
        self.start()
        if not self._started:  # no domain free, now either
            assert self._no_domain is not None
            raise self._no_domain
        if self._start_error is not None:
            raise self._start_error
        if self.process is not None:
            self.process.await_started()  # started ahead without waiting for it
        assert self.observer is not None
        opts = self.options
        waiting = time.monotonic()
        deadline = waiting + opts.ready_timeout
        clock_due = 0.0  # monotonic time of the next /clock while waiting
        observer = self.observer
        elsewhere = ElsewhereWatch(
            observer.node,
            opts,
            reads_scans=self._reads_scans,
            status_heard=lambda: observer.status_sub.get_publisher_count() > 0,
            watch=self.publishes_scans,  # a board's graph is the board's: no sign there
        )
        while not self._ready():
            gone = self.node_gone("before it was ready")
            if gone:
                raise LinkError(gone)
            expired = time.monotonic() >= deadline or elsewhere.settled()
            self._check_types(named_only=not expired)
            if expired:
                self._gave_up_early_s = elsewhere.gave_up_after
                raise NeverReady(self._never_ready())
            if self._clock_before_ready() and time.monotonic() >= clock_due:
                self.observer.publish_clock(0.0)  # a node may wait for /clock before it subscribes
                clock_due = time.monotonic() + POLL_S
            self.observer.spin(READY_POLL_S)
            self.observer.inbox.clear()  # nothing heard before it is ready is an answer
        self._ready_took = time.monotonic() - waiting
        if self.publishes_scans:  # its side matched too: the first scan is not repaired late
            self._wait_for(self.observer.scan_readers_named, NAMED_WAIT_S, poll=READY_POLL_S)
            self.observer.inbox.clear()
        self.startup_s = time.perf_counter() - started

    def _clock_before_ready(self) -> bool:
        """Publish /clock (time 0) while waiting for the node to come up?

        Yes in a graph the harness made for the node (a use_sim_time node
        reads time 0 until the first scan's /clock either way, so nothing it
        is judged on changes; one that waits for a /clock message before
        subscribing to the scans can start). Not into a physical board's
        graph, where nothing may be waiting for the harness's time.
        """
        return self.options.port is None

    def _reads_scans(self) -> bool:
        """Does something besides the harness read the scan topic?"""
        assert self.observer is not None
        obs = self.observer
        if obs.scan_pub is not None:
            return obs.scan_pub.get_subscription_count() > 0
        return obs.node.count_subscribers(self.options.scan_topic) > 1  # the harness's is one

    def _never_ready(self) -> str:
        """Why the node is not ready: what the harness waited for, and what was missing."""
        assert self.observer is not None
        obs, opts = self.observer, self.options
        reads = self._reads_scans()
        publishes = obs.status_sub.get_publisher_count() > 0
        return start_explanations.never_ready(
            self.command.description,
            opts,
            reads=reads,
            publishes=publishes,
            clock_all_along=self._clock_before_ready(),
            waited=start_explanations.ready_bound_said(opts.ready_timeout, self._gave_up_early_s),
            graph=obs.graph_summary(),
        ) + topic_hints(obs.node, opts, reads=reads, publishes=publishes)

    def _check_types(self, *, named_only: bool = False) -> None:
        """Fail at once, naming it, when the node publishes what can never reach the harness.

        With `named_only`, a wrong type waits until discovery has told which
        node owns the endpoint, so the explanation can name it.
        """
        assert self.observer is not None
        obs = self.observer
        why = start_explanations.unheard(
            self.command.description, obs.wrong_types(named_only=named_only), obs.qos_mismatches()
        )
        if why is not None:
            raise LinkError(why)

    # Hooks a link that delivers scans another way (a device and its driver)
    # overrides; the lockstep machinery below stays the same.
    def _start_processes(self, env: dict[str, str]) -> None:
        """Start the node under test."""
        args = node_arguments(self.command, node_parameters(self.options)) + self._remaps()
        held = None if self.domain is None else self.domain.fileno()
        self.process = NodeProcess(self.command, args, env, held=held)
        self.process.start(wait=False)  # open() waits: the next links start meanwhile
        self.node_start = f"{self.command.description}, {self.process.how}"

    def _remaps(self) -> list[str]:
        """Hook: ROS remapping arguments the node is started with (none: its own topics)."""
        return []

    def _make_observer(self, domain_id: int) -> Observer:
        return harness_observer(self.options, domain_id, publish_scans=self.publishes_scans)

    def _ready(self) -> bool:
        assert self.observer is not None
        return self.observer.ready()

    def _deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        """Put the scan in front of the node; return its send time (system-clock ns)."""
        assert self.observer is not None
        return self.observer.publish(scan, clock=clock)

    def _reached_node(self) -> bool:
        """Did the scan `_deliver` just sent reach the node? (A board may drop one.)"""
        return True

    def send_first(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        """Send the run's first scan until the node answers a copy (bounded by the ready
        timeout); `collect` then takes that answer as this tick's.

        Ready means our endpoints matched the node's; whether its endpoints
        matched ours is known only once an answer came, so a scan or answer
        sent before may be lost: the scan goes again after WARM_UP_RETRY_S,
        then twice as long each time (up to FIRST_RETRY_MAX_S), so a node slow
        on its first scan is not sent many. The node sees nothing but this
        scan before its first answer, which is judged. A node that dies
        meanwhile is left for `collect` to report, at this tick.
        """
        assert self.observer is not None
        obs, opts = self.observer, self.options
        self._await_bool_writer()  # its first Bool must reach us
        bool_matched = obs.warning_publishers() > 0
        self._flood.restart(obs.heard["status"], obs.heard["warning"])
        first_at = time.perf_counter()
        deadline = first_at + opts.ready_timeout
        first_ns = time.time_ns()
        copies, retry = 0, WARM_UP_RETRY_S
        while True:
            if copies:  # what answers an earlier copy answers no tick
                self._sends[-1] = (None, self._sends[-1][1])
            self._started_at = None  # real time counts from the copy that is answered
            self._copy(copies)
            self.send(scan, tick, clock=clock)
            copies += 1
            if not self._reached_node():
                break  # no answer can come (a board that published no scan of it)
            outcome = self._wait_for(self._answered, min(retry, deadline - time.perf_counter()))
            retry = min(2 * retry, FIRST_RETRY_MAX_S)
            if outcome != "timeout":
                break  # answered; or the node is gone, which collect reports at this tick
            self._check_types()
            if time.perf_counter() >= deadline:  # judged at this tick (collect): silent
                self._first_silence = start_explanations.never_answered(
                    self.command.description, opts, scan, copies
                )
                self._first_waited = time.perf_counter() - first_at
                break
        self._copies = copies
        if self._first_silence is None and not bool_matched:
            self._await_first_bool(first_ns)
        if copies > 1 and self.copies_queue and self._first_silence is None:
            # A node slow on its first scan has the other copies queued: let it answer
            # them (each about as long as the first took) before the next scan goes out,
            # or their answers would be taken for that scan's.
            took = time.perf_counter() - first_at
            self._wait_for(
                lambda: self._statuses_since(first_ns) >= copies,
                min(max(WARM_UP_RETRY_S, copies * took), opts.ready_timeout),
            )
        self._wait_for(
            lambda: not obs.wrong_types() or bool(obs.wrong_types(named_only=True)),
            WARM_UP_RETRY_S,
        )
        if self.node_gone() is None:
            self._check_types()
        self._warmed_up = True

    def _await_bool_writer(self) -> None:
        """Before the first scan, our Bool reader matched to the node's Bool writer, or
        its first Bool would be dropped as a stranger's.

        A node's writers and readers are announced on two channels in no common
        order, so ready (its scan reader and status writer matched) can come
        before its Bool writer is known: wait for the match while the graph shows
        a Bool writer, and a moment (BOOL_DISCOVERY_S) for one to show at all.
        """
        assert self.observer is not None
        obs, topic = self.observer, self.options.warning_topic
        if obs.warning_publishers() > 0:
            return
        if obs.node.count_publishers(topic) == 0:
            # As long as the graph took to show the node ready (a busy machine's
            # discovery is slower), and BOOL_DISCOVERY_S at least.
            bound = max(BOOL_DISCOVERY_S, self._ready_took)
            self._wait_for(lambda: obs.node.count_publishers(topic) > 0, bound)
        if obs.node.count_publishers(topic) > 0:
            self._wait_for(lambda: obs.warning_publishers() > 0, WARM_UP_RETRY_S)

    def _await_first_bool(self, first_ns: int) -> None:
        """The first scan went out while our Bool reader had matched no Bool writer, and
        it was answered without a Bool: where the node does have a Bool writer (the
        graph shows it only now, as a loaded machine's discovery may), the Bool it
        published before the match reaches us once Fast DDS repairs it. Wait for it,
        bounded by the per-scan deadline, so tick 0 is judged on the Bool the node
        published, not on discovery's speed."""
        assert self.observer is not None
        obs, topic = self.observer, self.options.warning_topic
        if obs.heard_since("warning", first_ns):
            return
        bool_writers = [
            info
            for info in obs.node.get_publishers_info_by_topic(topic)
            if info.topic_type == BOOL_TYPE
        ]
        if obs.warning_publishers() == 0 and not bool_writers:
            return  # no Bool writer in sight, even now (another type is named elsewhere)
        self._wait_for(lambda: obs.heard_since("warning", first_ns), self.options.scan_timeout)

    def _copy(self, n: int) -> None:
        """Hook: copy `n` (0 first) of the first scan is about to go out."""

    def _statuses_since(self, source_ns: int) -> int:
        assert self.observer is not None
        return sum(
            1 for h in self.observer.inbox if h.kind == "status" and h.source_ns >= source_ns
        )

    def warm_up(self, scan: Scan) -> None:
        """Exchange a scan until the node's answer reaches us, then forget it (the
        benchmarks' untimed first exchange, and a run whose first scan a node may ignore).

        Our subscriptions matching the node's publishers does not mean its
        publishers have matched us yet: its first answers could be lost.
        Also wait (briefly) for its warning publisher, if it has one.
        """
        assert self.observer is not None
        obs, opts = self.observer, self.options
        deadline = time.perf_counter() + opts.ready_timeout
        copies = 0
        while True:
            sent_ns = self._deliver(scan, -1)
            copies += 1
            if not self._reached_node():
                break  # no answer can come (a board that published no scan of it)

            def answered(since: int = sent_ns) -> bool:
                return obs.heard_since("status", since)

            outcome = self._wait_for(answered, min(WARM_UP_RETRY_S, deadline - time.perf_counter()))
            if outcome is None:
                break
            if outcome != "timeout":  # it names the node (or the driver, or the line) already
                raise LinkError(self.node_gone("while warming up") or outcome)
            # Ready may have counted a publisher the node has since replaced (a reliable
            # one swapped for best-effort, say): what can never be heard is said now.
            self._check_types()
            if time.perf_counter() >= deadline:
                raise LinkError(
                    start_explanations.never_answered(self.command.description, opts, scan, copies)
                )
        if obs.node.count_publishers(opts.warning_topic) > 0:
            self._wait_for(lambda: obs.warning_publishers() > 0, WARM_UP_RETRY_S)
        # By now the node's other publishers are known too; give discovery a
        # moment to tie a wrongly typed one to its node, so the error names it.
        self._wait_for(
            lambda: not obs.wrong_types() or bool(obs.wrong_types(named_only=True)),
            WARM_UP_RETRY_S,
        )
        self._check_types()
        self._wait_for(lambda: False, self._grace())  # the answer's Bool, if any
        obs.drain()
        obs.inbox.clear()
        self._flood.restart(obs.heard["status"], obs.heard["warning"])
        self._warmed_up = True

    def stop(self) -> None:
        """Close the harness's ROS node and ask the node under test to stop; `close` waits."""
        if self.observer is not None:
            self.observer.close()
        if self.process is not None:
            self.process.request_stop()

    def close(self) -> None:
        self.stop()
        if self.process is not None:
            self.process.stop()
        if self.domain is not None:
            self.domain.release()

    def stop_note(self) -> str:
        """After `close`: what stopping the node took beyond a plain SIGINT, if anything."""
        note = self.process.stop_note() if self.process is not None else ""
        return f"stopping node {self.command.description}: {note}" if note else ""

    def diagnostics(self) -> str:
        """The node's last output and what the graph showed; then ask the node to stop.

        The runner asks for diagnostics once, when the run is over (before
        closing the link). Its output is taken first, so its shutdown
        messages do not push out the lines that matter; how the stop went
        (killed, processes left behind) is `stop_note`, after `close`.
        """
        if self.process is None:
            return ""
        parts = output_notes(self.process)
        parts += self._wiring.graph_notes(
            self.observer, warmed_up=self._warmed_up, running=not self._node_exited()
        )
        self.stop()
        return "\n".join(parts)

    def notices(self) -> list[str]:
        """How the node is wired, then what its launch files get wrong (node_notes)."""
        return self._wiring.notices(
            self.observer, warmed_up=self._warmed_up, running=not self._node_exited()
        )

    # -- lockstep ---------------------------------------------------------
    def send(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        assert self.observer is not None, "open() the link first"
        now = scan.stamp if clock is None else clock
        if self.options.realtime:
            self._pace(now)
        if self._delay:  # a delayed scan: its time (paced or not) plus the delay
            delay, self._delay = self._delay, 0.0
            self._wait_for(lambda: False, delay)
        self._sent_ns = self._deliver(scan, tick, clock=now)
        self._sent_at = time.perf_counter()
        self._sends = [*self._sends[-7:], (tick, self._sent_ns)]

    def _pace(self, clock: float) -> None:
        """Real time: a scan taken at `clock` goes out that long after the first one,
        hearing answers meanwhile (a drifting rate keeps its own spacing)."""
        assert self.observer is not None
        if self._started_at is None:
            self._started_at = time.perf_counter() - clock
            return
        due = self._started_at + clock
        while (left := due - time.perf_counter()) > 0:
            self.observer.spin(min(POLL_S, left))

    def hold(self, seconds: float) -> None:
        """Delay the next scan; the node is heard while the delay passes (in `send`)."""
        self._delay = seconds

    def _deadline(self, scan: Scan) -> float:
        """Seconds a scan's answers may take: in real time, also before the next scan."""
        if self.options.realtime:
            return min(self.options.scan_timeout, scan.scan_time)
        return self.options.scan_timeout

    def _grace(self) -> float:
        if self._bool_first_seen and not self._bool_after_gap:
            return 0.0
        return min(max(MIN_GRACE_S, 4 * self._bool_after_gap), self.options.scan_timeout)

    def _node_exited(self) -> bool:
        """Has the node under test itself (not a board's software) exited?"""
        return self.process is not None and self.process.returncode() is not None

    def _crash_summary(self) -> str:
        assert self.process is not None
        return self.process.crash_summary("on this scan")

    def node_gone(self, when: str = "") -> str | None:
        """Why a process this link started is no longer running, or None if all run
        (`when` says at what point, e.g. "during the session")."""
        assert self.process is not None
        if self.process.returncode() is not None:
            return f"node {self.command.description} {self.process.exit_summary(when)}"
        return None

    def _wait_for(
        self, done: Callable[[], bool], seconds: float, *, poll: float = POLL_S
    ) -> str | None:
        """Spin until `done()`; None if it came, else "timeout" or why the node is gone.

        The node's liveness is checked once per POLL_S (each check is a few
        system calls, which cost more than the spin when the answer is
        already there) and once more when the wait runs out, so a node that
        died is never reported as a timeout. A spin ends when a message
        arrives or after `poll`: shorter for what no message announces (the graph).
        """
        assert self.observer is not None
        end = time.perf_counter() + seconds
        while not done():
            now = time.perf_counter()
            timed_out = now >= end
            if timed_out or now >= self._alive_until:
                gone = self.node_gone()
                if gone:
                    self.observer.drain()
                    return None if done() else gone
                self._alive_until = now + POLL_S
                if timed_out:
                    return "timeout"
            self.observer.spin(min(poll, end - now))
        return None

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        assert self.observer is not None
        obs = self.observer
        answers = Answers()

        def mine(h: Heard) -> bool:
            return h.source_ns >= self._sent_ns

        def status_in() -> bool:
            return self._answered()

        def warning_in() -> bool:
            return obs.heard_since("warning", self._sent_ns)

        timeout = self._deadline(scan)
        silence, self._first_silence = self._first_silence, None
        if silence is not None:  # the first scan's copies went unanswered: nothing to wait for
            outcome: str | None = "timeout"
        else:
            outcome = self._wait_for(status_in, self._sent_at + timeout - time.perf_counter())
        if outcome == "timeout":
            answers.timed_out = True
            outcome = None
            opts = self.options
            if silence is None and not (opts.realtime or may_be_ignored or opts.late_ends_run):
                # The node is behind. Let it catch up before the next scan, or its
                # answer to this scan would be taken for an answer to the next one.
                outcome = self._wait_for(status_in, max(CATCH_UP_S, 3 * timeout))
                outcome = None if outcome == "timeout" else outcome
        answers.problem = outcome
        if outcome is not None and self._node_exited():
            answers.problem = f"node {self.command.description} {self._crash_summary()}"
            answers.crashed = True
        if status_in():
            self._wait_for(warning_in, self._grace())
            self._settle_answers()
            obs.drain()
        self._sort(answers, obs.inbox, mine)
        obs.inbox.clear()
        if len(answers.statuses) > 1 and answers.problem is None:
            answers.problem = self._strangers()
        if self._copies > 1:  # the first scan went more than once: one answer is this tick's
            self._one_answer_of_the_copies(answers)
        self._copies = 1
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
        heard = self.observer.heard
        self._flood.see(
            answers, heard["status"], heard["warning"], time.perf_counter() - self._sent_at
        )
        return answers

    def _strangers(self) -> str | None:
        assert self.observer is not None
        domain_id = self.domain.domain_id if self.domain is not None else None
        return strangers_problem(self.observer.strangers(), domain_id)

    def _one_answer_of_the_copies(self, answers: Answers) -> None:
        """The first scan went out several times: keep the first copy's answer (the node saw
        nothing before it; the later ones become late answers of no tick)."""
        answers.first_answer_only()

    def _settle_answers(self) -> None:
        """Hook: once the answers are in, anything else to wait (briefly) for."""

    def _answered(self) -> bool:
        """Has the status answering the scan just sent arrived?"""
        assert self.observer is not None
        return self.observer.heard_since("status", self._sent_ns)

    def _sort(self, answers: Answers, heard: Iterable[Heard], mine) -> None:
        """Split what arrived into this scan's answers and late ones; learn the Bool order."""
        first_status = next((h for h in heard if h.kind == "status" and mine(h)), None)
        string_first = self._bool_after_gap > 0 and not self._bool_first_seen
        for h in heard:
            if h.kind == "scan":
                continue  # a driver's scan (serial links): not an answer
            item = Received(h.value, h.arrived - self._sent_at, source_ns=h.source_ns)
            if not mine(h):
                answers.late.append(Received(h.value, item.after, self._tick_of(h.source_ns)))
            elif h.kind == "status":
                answers.statuses.append(item)
            elif (
                string_first
                and first_status is not None
                and h.source_ns < first_status.source_ns
                and len(self._sends) > 1
            ):
                # A node that publishes its Bool after its String, caught
                # between the two (a busy thread holding its GIL) until this
                # scan had gone out: the Bool answers the scan before.
                answers.late.append(Received(h.value, item.after, self._sends[-2][0]))
            else:
                answers.warnings.append(item)
                if first_status is not None:
                    if h.source_ns <= first_status.source_ns:
                        self._bool_first_seen += 1
                    else:
                        gap = (h.source_ns - first_status.source_ns) / 1e9
                        self._bool_after_gap = max(self._bool_after_gap, gap, 1e-4)

    def _tick_of(self, source_ns: int) -> int | None:
        """The last scan sent before the node published this message."""
        earlier = [tick for tick, sent in self._sends if sent <= source_ns]
        return earlier[-1] if earlier else None

    def settle(self) -> list[Received]:
        """Answers to the last scan that come after its status (e.g. a trailing Bool)."""
        if self.observer is None:
            return []
        end = time.perf_counter() + self._grace()
        while time.perf_counter() < end:
            self.observer.spin(end - time.perf_counter())
        self.observer.drain()
        self._settled()
        late = [
            Received(h.value, h.arrived - self._sent_at, self._tick_of(h.source_ns))
            for h in self.observer.inbox
            if h.kind != "scan"
        ]
        self.observer.inbox.clear()
        return late

    def _settled(self) -> None:
        """Hook: what `settle` heard is in the inbox, before its answers get their ticks."""
