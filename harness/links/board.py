"""Links through a LIDAR on a serial line: the harness plays the device.

Virtual board (default): a pty pair stands in for the USB cable; the board's
own software (the bundled LIDAR driver from node/fossbot_lidar_driver, or
the user's ``--board-command`` processes) reads the emulated device and
publishes /scan, and the node under test answers it, each in its own
process. Physical board (``--port``): the emulator drives a real USB-UART
wired to the board's LIDAR input in real time, and the harness joins the
board's ROS 2 graph to watch what it publishes.

The device, the line and the board's software live for the whole run
(``board_session.BoardSession``, the class's ``run_session``); each
scenario's link uses them, and on the virtual board starts a fresh node
under test. The lockstep machinery of the ros2 link is reused; only the
delivery differs: a scan becomes device samples, goes down the line, and
the driver's /scan for that revolution (quantised and re-binned) is what
the oracle judges, because it is what the node saw.

Which board scan is which revolution: the first scan the board published
after the write that carried the revolution's last byte (a driver can
publish a revolution only once it has all of it, and it has published the
one before by then, when it answers within a revolution's time). Scans of
revolutions the device sent on its own (repeats between scenarios, or
when the harness was late) are told apart the same way and not judged.
"""

from __future__ import annotations

import copy
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, ClassVar

from harness.devices.profiles import DeviceProfile
from harness.errors import ConfigError
from harness.faults.link import LineDamage
from harness.judge.answers import Answers
from harness.lidar.mount import LidarMount
from harness.lidar.scan import Scan
from harness.links.base import LinkOptions
from harness.links.board_idle import (
    IDLE_LAST_ANSWER_S,
    IdleStreamEnd,
    set_aside_answers_to_the_idle_stream,
)
from harness.links.board_pairing import AnswerWindow, owed_answers, pair_with_driver_scans
from harness.links.board_session import BoardSession, board_options, remappable, takes_remaps
from harness.links.node_start import harness_observer, node_command
from harness.links.ros2 import POLL_S, Ros2Link
from harness.ros.observer import Heard, Observer

if TYPE_CHECKING:
    from harness.serial_line.diagnosis import LineReport

SCAN_CATCH_UP_S = 0.05  # a driver scan published before its answer reaches us within this
LATE_SCAN_WAIT_S = 0.2  # after a lost revolution: how long a second driver scan may follow
LOST_IN_A_ROW = 5  # line faults: this many revolutions without a driver scan is a failure
# A driver may skip a revolution with this few returns: rplidar's iter_scans
# (the FOSSBot v2's agent) yields none of 5 or fewer.
SPARSE_RETURNS = 5
SPARSE_WAIT_S = 0.25  # at least this long for the board's scan of such a revolution


class BoardLink(IdleStreamEnd, Ros2Link):
    """A LIDAR device emulated on a serial line, read by the board's own driver."""

    sets_node_topics = False  # the board's driver publishes the scan topic for the run

    profile: ClassVar[DeviceProfile]
    serial_line = True
    publishes_scans = False  # the board's driver publishes /scan; the harness listens
    # A revolution the node did not answer in time never reached it (its subscription
    # was still matching), and the device must not be kept waiting while the node
    # answers nothing: the driver gives up on a silent line.
    copies_queue = False
    # One line, one board; but on the virtual board the next scenario's node comes up
    # while this one runs, answering on topics of its own (`links_ahead`).
    starts_ahead = True

    def __init__(self, options: LinkOptions, session: BoardSession | None = None) -> None:
        options = board_options(options)
        if session is not None:  # the run's device and domain
            options = replace(options, domain_id=session.domain_id)
        super().__init__(options)
        self.physical = options.port is not None
        self.session = session
        self._own_session = session is None  # one scenario on its own: its own device
        self._pushed = False  # the first push ends the session's idle stream
        self._gap_measured = False
        self._seen: Scan | None = None
        self._delivery_problem: str | None = None
        self._lost: str | None = None  # why the driver made no scan of it (not a failure)
        self._scans_from = 0  # source time of the first driver scan of this revolution
        self._lost_in_a_row = 0
        self._heard_scans: list[Heard] = []
        self._repeat_at: int | None = None  # the first repeat's scan in this exchange, if any
        self._window: AnswerWindow | None = None  # the last tick's scans and answers
        self._owed = 0  # statuses after this tick's scan that answer earlier scans
        self._line_damage: LineDamage | None = None
        self._first_damage: LineDamage | None = None  # as it was before the first scan's copy
        self._after_first: LineDamage | None = None  # as it was after it (copies were sent)
        self._after_idle = False  # the first exchange after the idle stream is next
        # The node may still answer idle revolutions during the first tick (it lagged, or
        # answered none before the first tick, so how many it owes is not known).
        self._idle_owed = False
        self._idle_quiet_s = 0.0  # three revolutions at the first scan's rate
        # The node's status and warning topics, its own in the run's domain (remapped),
        # or None: the options' (no session shared, a physical board, a launch file).
        self._own_topics: tuple[str, str] | None = None
        if session is not None and not self.physical and takes_remaps(self.command):
            self._own_topics = session.node_topics(options.status_topic, options.warning_topic)

    @classmethod
    def links_ahead(cls, options: LinkOptions) -> int:
        """How many links a suite starts beyond the running one: on the virtual board the
        next, so its node and world are ready before this scenario's last revolution. It
        hears this scenario's scans on the board's scan topic but answers on topics of its
        own (``BoardSession.node_topics``), which only its own link hears. None on a
        physical board, for a node a launch file starts, or for private topic names."""
        if options.port is not None or not remappable(options.status_topic, options.warning_topic):
            return 0
        try:
            command = node_command(options)
        except ConfigError:
            return 0  # reported where the link is made
        return 1 if takes_remaps(command) else 0

    @classmethod
    def run_session(cls, options: LinkOptions) -> BoardSession:
        """One device, line and board for the whole run (see board_session)."""
        return BoardSession(cls.profile, board_options(options))

    # -- the session's parts ------------------------------------------------
    @property
    def device(self) -> Any:
        assert self.session is not None, "start() the link first"
        return self.session.device

    @property
    def server(self) -> Any:
        return self.session.server if self.session is not None else None

    @property
    def port(self) -> Any:
        return self.session.port if self.session is not None else None

    @property
    def mount(self) -> LidarMount:
        """How the device sits on the robot: one mount for the run (the session's)."""
        assert self.session is not None, "start() the link first"
        return self.session.mount

    # -- processes and ports ----------------------------------------------
    @classmethod
    def prepare(cls, options: LinkOptions) -> None:
        """Start the fork server of the virtual board's node under test."""
        if options.port is None:
            super().prepare(options)

    def start(self) -> None:
        """Open this link's own session if it has none (a scenario run on its own)."""
        if self.session is None and not self._started:
            try:
                self.session = BoardSession(self.profile, self.options).open()
            except Exception as err:  # raised again by open(), as a start failure
                self._started, self._start_error = True, err
                return
            self.options = replace(self.options, domain_id=self.session.domain_id)
        super().start()

    def _start_processes(self, env: dict[str, str]) -> None:
        if not self.physical:  # a physical board's software runs its nodes
            super()._start_processes(env)

    def _remaps(self) -> list[str]:
        """The node answers on its own topics where it has them (`links_ahead`)."""
        if self._own_topics is None:
            return []
        opts, (status, warning) = self.options, self._own_topics
        return ["-r", f"{opts.status_topic}:={status}", "-r", f"{opts.warning_topic}:={warning}"]

    def _make_observer(self, domain_id: int) -> Observer:
        """The harness's node in the run's domain, hearing this link's node only: on its
        own topics where it has them."""
        options = self.options
        if self._own_topics is not None:
            status, warning = self._own_topics
            options = replace(options, status_topic=status, warning_topic=warning)
        return harness_observer(options, domain_id, publish_scans=False)

    def open(self) -> None:
        """As the ros2 link's; what the observer heard before (a link started ahead, while
        the scenario before ran) answers nothing of this scenario's; the device takes
        this scenario's rate (not at `start`: the scenario before may still run)."""
        super().open()
        assert self.observer is not None and self.session is not None
        self.observer.inbox.clear()
        self.session.set_rate(self.options.scan_rate_hz)  # its turn: the device spins at its rate

    def _ready(self) -> bool:
        assert self.observer is not None and self.server is not None
        if not self.profile.streams_unasked and self.device.mode == "idle":
            return False  # the driver has not asked for a scan yet
        return self.observer.ready()

    def _never_ready(self) -> str:
        """A board that never answers: what went down the line, what came back, and why."""
        if not self.physical or self.server is None:
            return super()._never_ready()
        ready = (
            f"the board never became ready within {self.options.ready_timeout:g} s "
            f"({self.profile.description})"
        )
        graph = self.observer.graph_summary() if self.observer is not None else ""
        report = self.line_diagnosis()
        if not report.likely or self.profile.streams_unasked:
            # Nothing wrong on the line (an LD06/LD19's line cannot tell, even after
            # streaming for a while: its driver sends nothing back): what was missing
            # is on the board's ROS 2 side.
            quiet = (
                "an LD06/LD19 driver sends nothing back, so the line cannot tell"
                if self.profile.streams_unasked
                else "the line looks right"
            )
            domain = self.domain.domain_id if self.domain is not None else "?"
            report = replace(
                report,
                likely=f"{quiet}; the board's nodes were not ready in ROS domain {domain}: "
                "check that it is the board's ROS_DOMAIN_ID, --ros-network (the board is "
                "another machine), and that its LIDAR driver and node run",
            )
        line = report.text()
        return f"{ready}: on the line {line}" + (f" ({graph})" if graph else "")

    def line_report(self) -> str:
        """The serial line's story: sent, came back, likely cause (for errors)."""
        return self.line_diagnosis().text()

    def line_diagnosis(self) -> LineReport:
        """The serial line's story in its three parts."""
        from harness.serial_line.diagnosis import diagnose

        assert self.server is not None and self.port is not None
        return diagnose(
            self.server.stats(),
            port=f"--port {self.port.name}" if self.physical else self.port.name,
            baudrate=self.profile.baudrate,
            streams_unasked=self.profile.streams_unasked,
        )

    def node_gone(self, when: str = "") -> str | None:
        gone = self.session.gone(when) if self.session is not None else None
        if gone is not None:
            return gone
        return None if self.physical else super().node_gone(when)

    def damage_line(self, damage: LineDamage) -> None:
        """Line faults: the device's revolutions reach the driver damaged from the next
        push on (until this scenario ends); the idle stream before it never is.

        A revolution the driver then publishes no scan of is lost, not a
        broken link: the node had nothing to answer.
        """
        assert self.server is not None, "open() the link first"
        self._line_damage = damage
        if self._pushed:
            self.server.damage = damage

    # -- delivery ---------------------------------------------------------
    def _deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        """Send the revolution down the line; wait (bounded) for the driver's /scan of it."""
        assert self.observer is not None and self.server is not None
        obs = self.observer
        obs.publish_clock(scan.stamp if clock is None else clock)
        rate = self._rate(scan)
        samples = self.profile.revolution(self.device, scan, rate, scan.range_max, mount=self.mount)
        returns = sum(1 for sample in samples if sample.distance_mm > 0)
        self._seen, self._delivery_problem, self._lost = None, None, None
        window, self._window, self._owed = self._window, None, 0
        if not self._pushed:  # this scenario's first revolution: the idle stream ends
            self._idle_over(rate)
        written_ns = self._push(samples, tick, rate)
        if written_ns is None:
            return time.time_ns()

        def driver_scan() -> Any:
            return next(
                (h for h in obs.inbox if h.kind == "scan" and h.source_ns >= written_ns), None
            )

        wait = max(self.options.scan_timeout, 1.0 / rate)
        sparse = returns <= SPARSE_RETURNS
        if sparse:  # the board may never publish it: do not wait a whole deadline
            skips = self.session.skips_sparse
            wait = 0.0 if skips else min(wait, max(2.0 / rate, SPARSE_WAIT_S))
        deadline = time.perf_counter() + wait
        while (heard := driver_scan()) is None:
            gone = self.node_gone()
            if gone or time.perf_counter() >= deadline:
                if not gone and sparse:
                    # A board that skipped one such turn is taken to skip them all: the
                    # next are not waited for (a scan that comes after all is told
                    # apart by time, and not judged).
                    self.session.skips_sparse = True
                    self._lost = (
                        f"the board published no {self.options.scan_topic} of this revolution: "
                        f"it had {returns} return{'' if returns == 1 else 's'}, and a driver may "
                        f"skip so sparse a turn (rplidar's iter_scans skips {SPARSE_RETURNS} or "
                        "fewer)"
                    )
                    return time.time_ns()
                return self._no_driver_scan(gone)
            obs.spin(min(POLL_S, deadline - time.perf_counter()))
        if sparse:
            self.session.skips_sparse = False
        repeats = self._not_this_revolution(written_ns)
        if self._line_damage is None and tick > 0:
            late = sum(1 for h in obs.inbox if h.kind == "status" and h.source_ns < heard.source_ns)
            self._owed = owed_answers(window, repeats, late)
        self._seen = heard.value
        self._scans_from = heard.source_ns
        if self._lost_in_a_row:
            # The last revolution made no scan in time: this one may be it, late (the
            # line ate what closed it), with this revolution's own scan just behind.
            self._wait_for(lambda: len(self._driver_scans()) >= 2, LATE_SCAN_WAIT_S)
        self._lost_in_a_row = 0
        return heard.source_ns

    def warm_up(self, scan: Scan) -> None:
        """As the ros2 link's; then the stream ends on a whole start marker, so the
        scenario's revolutions are the same bytes however many warm-up pushes it took."""
        super().warm_up(scan)
        assert self.server is not None
        self.server.align_stream()

    def send_first(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        """As the ros2 link's, once the node has answered what the device streamed while
        it came up (those answers are not judged); then, as after a warm-up, the stream
        ends on a whole start marker, so the later revolutions are the same bytes however
        many copies of the first it took."""
        self._end_idle_stream(scan)
        self._after_idle = True
        super().send_first(scan, tick, clock=clock)
        self._after_copies()
        assert self.server is not None
        self.server.align_stream()

    def _copy(self, n: int) -> None:
        """Each later copy of the first scan is damaged from the line's state before the
        first copy, by a scratch copy of it, after the stream was ended on a whole start
        marker (so its bytes are the first's: the first came after the idle stream's),
        and once the copies are out the line goes on from its state after the first copy
        (`_after_copies`): what the driver makes of each copy, the line's damage from
        then on, and its counts do not depend on how many copies it took."""
        assert self.server is not None
        if self._line_damage is None:
            return
        if n == 0:
            self._first_damage = copy.deepcopy(self._line_damage)
            return
        if n == 1:
            self._after_first = self._line_damage
        self.server.align_stream()  # the copy's bytes are the first's
        if self._first_damage is not None:
            self.server.damage = copy.deepcopy(self._first_damage)

    def _after_copies(self) -> None:
        assert self.server is not None
        if self._after_first is not None:
            self._line_damage, self._after_first = self._after_first, None
            self.server.damage = self._line_damage

    def _rate(self, scan: Scan) -> float:
        return 1.0 / scan.scan_time if scan.scan_time > 0 else self.options.scan_rate_hz

    def _reached_node(self) -> bool:
        return self._lost is None  # a revolution the board published no scan of: lost

    def _push(self, samples: list[Any], tick: int, rate: float) -> int | None:
        """Queue the revolution and wait (bounded) until it went out whole; the system time
        before its last write, or None (the reason kept in `_delivery_problem`).

        A device the board's driver stopped (a driver restarting: STOP, RESET,
        ... SCAN) is waited for, as long as a board may take to come up, and
        the revolution goes out again once it scans.
        """
        assert self.server is not None and self.observer is not None
        server, period = self.server, 1.0 / rate
        push = server.send_revolution(samples, tick, period)
        limit = self.options.scan_timeout + (3 * period if server.mode == "realtime" else 0.0)
        deadline = time.perf_counter() + limit
        while (delivery := server.delivery_of(push)) is None:
            gone = self.node_gone()
            if gone is not None:
                self._delivery_problem = gone
                return None
            if not self.profile.streams_unasked and self.device.mode == "idle":
                if not server.wait_until(lambda d: d.mode != "idle", self.options.ready_timeout):
                    self._delivery_problem = (
                        f"the device stopped scanning and the board's driver did not ask "
                        f"again within {self.options.ready_timeout:g} s (on the line: "
                        f"{self.line_report()})"
                    )
                    return None
                push = server.send_revolution(samples, tick, period)
                deadline = time.perf_counter() + limit
            elif time.perf_counter() >= deadline:
                self._delivery_problem = (
                    f"the device could not send this revolution within {limit:.2f} s "
                    f"(on the line: {self.line_report()})"
                )
                return None
            self.observer.spin(POLL_S / 5)
        return delivery.written_ns

    def _no_driver_scan(self, gone: str | None) -> int:
        """No driver scan of the revolution in time: lost on a damaged line, else a failure."""
        missing = (
            f"the board's driver published no {self.options.scan_topic} for this revolution in time"
        )
        self._lost_in_a_row += 1
        if not gone and self._line_damage is not None:
            if self._lost_in_a_row < LOST_IN_A_ROW:
                self._lost = f"{missing} (damaged on the line)"
                return time.time_ns()
            missing = (
                f"the board's driver published no {self.options.scan_topic} for "
                f"{self._lost_in_a_row} revolutions in a row (line faults lose some, "
                "not all)"
            )
        if not gone and self.physical:
            missing += f" (on the line: {self.line_report()})"
        self._delivery_problem = gone or missing
        return time.time_ns()

    def _not_this_revolution(self, written_ns: int) -> int:
        """Driver scans of revolutions the device sent on its own (a repeat while the
        harness was late) came before this one's: answers to them answer no tick. How
        many came."""
        assert self.observer is not None
        others = sorted(
            h.source_ns
            for h in self.observer.inbox
            if h.kind == "scan" and self._scans_from < h.source_ns < written_ns
        )
        self._sends = [*self._sends, *((None, ns) for ns in others)]
        return len(others)

    def _driver_scans(self) -> list[Heard]:
        """The driver's scans of this exchange, oldest first: its revolution's, and on a
        damaged line the ones the line made late or split (not the device's repeats)."""
        assert self.observer is not None
        since, until = self._scans_from, self._repeat_from()
        return [
            h
            for h in self.observer.inbox
            if h.kind == "scan" and since <= h.source_ns and (until is None or h.source_ns < until)
        ]

    def _repeat_from(self) -> int | None:
        """When the first scan of a revolution the device sent again on its own came (the
        harness slower than a revolution: real time), or None. The node answers in
        order: its first answer is this tick's, the next ones the repeats'. With line
        faults a later scan may be this revolution split or made late instead
        (`_pair_with_driver_scans`)."""
        if self._line_damage is not None or self.observer is None:
            return None
        since = self._scans_from
        later = [
            h.source_ns for h in self.observer.inbox if h.kind == "scan" and h.source_ns > since
        ]
        return min(later) if later else None

    def _statuses(self) -> int:
        assert self.observer is not None
        since = self._sent_ns
        return sum(1 for h in self.observer.inbox if h.kind == "status" and h.source_ns >= since)

    def _answered(self) -> bool:
        """One status for each driver scan this exchange brought (usually one)."""
        return self._statuses() >= max(len(self._driver_scans()), 1) + self._owed

    def _settle_answers(self) -> None:
        """The first tick, when the node may still owe answers to idle revolutions: wait
        (bounded) until it has been quiet for three revolutions, so its answer to this
        tick, which comes after those, is in (`collect` keeps the last).

        Line faults: more statuses than driver scans heard may mean a late scan's
        answer overtook the scan on its way to us (two topics, two readers). Wait a
        moment for it; a node that simply answers twice costs that moment."""
        if self._after_idle and (self._idle_owed or self._copies > 1):
            # A copy went unanswered: the node was behind, and still answers the idle
            # stream's scans and the copies, in order, after the first status came.
            self._wait_for(self._statuses_quiet, IDLE_LAST_ANSWER_S)
        if self._line_damage is not None and self._statuses() > len(self._driver_scans()):
            self._wait_for(lambda: len(self._driver_scans()) >= self._statuses(), SCAN_CATCH_UP_S)

    def _one_answer_of_the_copies(self, answers: Answers) -> None:
        """Not the first copy's answer, as over ROS 2: idle revolutions came before the
        copies, and the node answers in order, so the last answer is the last copy's
        (`collect` keeps it, setting aside what answered the idle stream)."""

    def _between_scenarios(self, tick: int) -> None:
        """This scenario's first tick is out (its driver scan came, or it was lost): the
        gap since the scenario before's last tick ended (``gap_s``; its ticks at the
        end that the board made no scan of belong to it, not to the gap)."""
        if tick < 0 or self._gap_measured or self.session is None:
            return
        self._gap_measured = True
        if self.session.last_tick_at is not None:  # a scenario ran before on this device
            self.gap_s = time.perf_counter() - self.session.last_tick_at

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        self._between_scenarios(tick)
        if self._lost is not None:
            # The node never got this revolution: nothing to wait for. What it
            # publishes meanwhile is sorted by the next exchange, by send time.
            if self.session is not None:
                self.session.last_tick_at = time.perf_counter()
            return Answers(lost=self._lost)
        assert self.observer is not None
        self._heard_scans = []
        answers = super().collect(scan, tick, may_be_ignored=may_be_ignored)
        if self._after_idle:
            self._after_idle = False
            set_aside_answers_to_the_idle_stream(answers, len(self._heard_scans))
            answers.owed_before = True  # its answers still to come are newer: this tick's
        pair_with_driver_scans(answers, self._heard_scans)
        if self._repeat_at is not None:  # answers to the device's repeats answer no tick
            answers.first_answer_only()
            self._sends = [*self._sends, (None, self._repeat_at)]
        if answers.seen is None:
            answers.seen = self._seen
        answers.lost = self._lost
        if self._delivery_problem and answers.problem is None:
            answers.problem = self._delivery_problem
        if self.session is not None:
            self.session.last_tick_at = time.perf_counter()
        return answers

    def _settled(self) -> None:
        """While the last scan's trailing answers are awaited, the device may repeat its
        revolution on its own: the answers to those repeats answer no tick (as in
        `collect`), never the last tick twice."""
        repeat = self._repeat_from()
        if repeat is not None:
            self._sends = [*self._sends, (None, repeat)]

    def _sort(self, answers: Answers, heard: Any, mine: Any) -> None:
        """Keep the driver's scans of this exchange, in order, for pairing, and when the
        device's first repeat came."""
        self._heard_scans = self._driver_scans()  # `heard` is the inbox they are read from
        self._repeat_at = self._repeat_from()
        super()._sort(answers, heard, mine)
        if self._owed:  # the first statuses answer scans before this tick's (owed_answers)
            answers.keep_only(sorted(answers.statuses, key=lambda r: r.source_ns)[self._owed :])
        statuses = sum(1 for h in heard if h.kind == "status" and h.source_ns >= self._sent_ns)
        after = sum(1 for h in heard if h.kind == "scan" and h.source_ns > self._scans_from)
        # Owed answers that never came (a node that skips a repeat) are not carried on.
        plain = self._line_damage is None and self._copies == 1
        plain = plain and not (self._owed and answers.timed_out)
        self._window = AnswerWindow(1 + after, max(0, statuses - self._owed)) if plain else None

    # -- reporting and teardown ---------------------------------------------
    def diagnostics(self) -> str:
        parts = [super().diagnostics()] if not self.physical else []
        if self.session is not None:
            parts.append(self.session.diagnostics())
        return "\n".join(p for p in parts if p)

    def stop(self) -> None:
        """The scenario is over: the device streams on (the run's session), the node stops."""
        if self.session is not None and not self._own_session:
            if self.server is not None:
                self.server.damage = None  # line faults are the scenario's
            self.session.between()
        super().stop()

    def close(self) -> None:
        self.stop()
        super().close()
        if self.session is not None and self._own_session:
            self.session.close()

    def stop_note(self) -> str:
        notes = [super().stop_note()]
        if self.session is not None and self._own_session:
            notes.append(self.session.stop_note())
        return "\n".join(n for n in notes if n)
