"""The node under test and the harness's own ROS node, in one domain, for one scenario.

Reserves the domain, starts both without waiting (a suite starts the next links while
one runs), waits bounded for readiness, names what can never reach the harness and
stops what it started; a physical board's software is none of its processes
(``runs_node``). Its ``wait_for`` is the one bounded wait every exchange spins in."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from harness.errors import LinkError, NeverReady
from harness.links import start_explanations
from harness.links.base import LinkOptions
from harness.links.bounds import NAMED_WAIT_S, POLL_S, READY_POLL_S
from harness.links.node_notes import WiringNotes, output_notes
from harness.links.node_start import harness_observer, node_parameters
from harness.links.topic_advice import ElsewhereWatch, topic_hints
from harness.nodes.command import NodeCommand, node_arguments
from harness.nodes.process import NodeProcess, start_would_wait
from harness.ros.domain import DomainReservation, NoFreeDomain, discovery_environment

if TYPE_CHECKING:
    from harness.ros.observer import Observer


@dataclass(frozen=True)
class GraphHooks:
    """What a link's graph does otherwise than the ros2 link's (each None: as it does)."""

    publishes_scans: bool = True  # the harness publishes the scans (a board's driver does)
    runs_node: bool = True  # start the node under test (a physical board runs its own)
    remaps: tuple[str, ...] = ()  # ROS remapping arguments the node is started with
    listen: LinkOptions | None = None  # the topics the harness's node hears (the options')
    # Ready also needs this (a board whose driver has asked the device to scan).
    ready: Callable[[], bool] | None = None
    # Why it never became ready, where the link knows better (a physical board's line).
    never_ready: Callable[[], str | None] | None = None
    gone: Callable[[str], str | None] | None = None  # what else may stop (a board's software)


class NodeGraph:
    """Start a node and the harness's node in a domain; wait, bounded, for it; stop both."""

    def __init__(
        self,
        options: LinkOptions,
        command: NodeCommand,
        wiring: WiringNotes,
        hooks: GraphHooks | None = None,
    ) -> None:
        self.options, self.command = options, command
        self.wiring = wiring  # the run's launch files, if any
        self.hooks = hooks or GraphHooks()
        self.process: NodeProcess | None = None
        self.observer: Observer | None = None
        self.domain: DomainReservation | None = None
        self.node_start = ""  # how the node under test was started, for the user
        self.started = False
        self._start_error: Exception | None = None
        self._no_domain: NoFreeDomain | None = None  # why start() could not start it yet
        self._alive_until = 0.0  # perf_counter until which the node counts as running
        self.ready_took = 0.0  # seconds `open` waited for the graph to show the node ready
        self._gave_up_early_s: float | None = None  # readiness abandoned early, after this

    def fail(self, err: Exception) -> None:
        """Keep `err` to raise from `open`, as if starting had failed."""
        self.started, self._start_error = True, err

    def start(self, reserve: Callable[[int | None], DomainReservation]) -> None:
        """Reserve a domain (by `reserve`), start the node and the harness's node; do not wait.

        A failure is kept for `open` to raise, so a link started ahead reports it in its own
        scenario; with no domain free the link stays unstarted and `open` tries again."""
        if self.started:
            return
        opts = self.options
        try:
            self.domain = reserve(opts.domain_id)
        except NoFreeDomain as err:
            self._no_domain = err
            return
        except Exception as err:  # raised again by open()
            self.fail(err)
            return
        self.started = True
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
        """Once `start` ran: wait, bounded, until the node is ready."""
        if not self.started:  # no domain free, now either
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
            watch=self.hooks.publishes_scans,  # a board's graph is the board's: no sign there
        )
        while not self._ready():
            gone = self.node_gone("before it was ready")
            if gone:
                raise LinkError(gone)
            expired = time.monotonic() >= deadline or elsewhere.settled()
            self.check_types(named_only=not expired)
            if expired:
                self._gave_up_early_s = elsewhere.gave_up_after
                raise NeverReady(self._never_ready())
            if self._clock_before_ready() and time.monotonic() >= clock_due:
                self.observer.publish_clock(0.0)  # a node may wait for /clock before it subscribes
                clock_due = time.monotonic() + POLL_S
            self.observer.spin(READY_POLL_S)
            self.observer.inbox.clear()  # nothing heard before it is ready is an answer
        self.ready_took = time.monotonic() - waiting
        if self.hooks.publishes_scans:  # its side matched too: the first scan is not repaired late
            self.wait_for(self.observer.scan_readers_named, NAMED_WAIT_S, poll=READY_POLL_S)
            self.observer.inbox.clear()

    def _clock_before_ready(self) -> bool:
        """/clock (time 0) while the node comes up, so one that waits for a clock before it
        subscribes can start (a use_sim_time node reads 0 until the first scan's anyway);
        never into a physical board's graph."""
        return self.options.port is None

    def _reads_scans(self) -> bool:
        """Does something besides the harness read the scan topic?"""
        assert self.observer is not None
        return self.observer.scan_readers() > 0

    def _never_ready(self) -> str:
        """Why the node is not ready: what the harness waited for, and what was missing."""
        if self.hooks.never_ready is not None:
            said = self.hooks.never_ready()
            if said is not None:
                return said
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

    def check_types(self, *, named_only: bool = False) -> None:
        """Fail at once, naming it, when the node publishes what can never reach the harness;
        `named_only`: wait until discovery tells which node owns the endpoint."""
        assert self.observer is not None
        obs = self.observer
        why = start_explanations.unheard(
            self.command.description, obs.wrong_types(named_only=named_only), obs.qos_mismatches()
        )
        if why is not None:
            raise LinkError(why)

    def _start_processes(self, env: dict[str, str]) -> None:
        """Start the node under test (unless the board runs its own)."""
        if not self.hooks.runs_node:
            return
        args = node_arguments(self.command, node_parameters(self.options)) + [*self.hooks.remaps]
        held = None if self.domain is None else self.domain.fileno()
        self.process = NodeProcess(self.command, args, env, held=held)
        self.process.start(wait=False)  # open() waits: the next links start meanwhile
        self.node_start = f"{self.command.description}, {self.process.how}"

    def _make_observer(self, domain_id: int) -> Observer:
        options = self.hooks.listen or self.options
        return harness_observer(options, domain_id, publish_scans=self.hooks.publishes_scans)

    def _ready(self) -> bool:
        assert self.observer is not None
        if self.hooks.ready is not None and not self.hooks.ready():
            return False
        return self.observer.ready()

    def node_exited(self) -> bool:
        """Has the node under test itself (not a board's software) exited?"""
        return self.process is not None and self.process.returncode() is not None

    def crash_summary(self) -> str:
        assert self.process is not None
        return self.process.crash_summary("on this scan")

    def node_gone(self, when: str = "") -> str | None:
        """Why a process this link started is no longer running, or None if all run
        (`when` says at what point, e.g. "during the session")."""
        if self.hooks.gone is not None:
            gone = self.hooks.gone(when)
            if gone is not None:
                return gone
        if self.process is None or self.process.returncode() is None:  # a physical board: elsewhere
            return None
        return f"node {self.command.description} {self.process.exit_summary(when)}"

    def wait_for(
        self, done: Callable[[], bool], seconds: float, *, poll: float = POLL_S
    ) -> str | None:
        """Spin until `done()`; None if it came, else "timeout" or why the node is gone.

        Liveness is checked once per POLL_S (its system calls cost more than a spin) and
        when the wait runs out, so a dead node is never reported as a timeout; a spin ends
        on a message or after `poll` (shorter for the graph, which no message announces)."""
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

    # -- the end ----------------------------------------------------------
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

    def diagnostics(self, *, warmed_up: bool) -> str:
        """The node's last output (taken first, before its shutdown messages) and what the
        graph showed (`warmed_up`: it answered); how the stop went is `stop_note`."""
        assert self.process is not None
        parts = output_notes(self.process)
        parts += self.wiring.graph_notes(
            self.observer, warmed_up=warmed_up, running=not self.node_exited()
        )
        return "\n".join(parts)

    def notices(self, *, warmed_up: bool) -> list[str]:
        """How the node is wired, then what its launch files get wrong (node_notes)."""
        return self.wiring.notices(
            self.observer, warmed_up=warmed_up, running=not self.node_exited()
        )
