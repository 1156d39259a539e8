"""The board delivery: a scan becomes a revolution of an emulated device, down the line.

The driver's scan of it (quantised and re-binned) is what the oracle judges: it is
what the node saw. The ``NodeExchange`` owns the waits and the pairing; this part owns
what a line and a device bring: the push, lost revolutions (sparse, or damaged), the
device's repeats, the idle stream's end (``board_idle``) and which answer answered
which driver scan (``board_pairing``). A revolution's scan is the first the board
published after the write carrying its last byte (a driver publishes a revolution
only once it has all of it); repeats the device sent on its own are told apart the
same way and not judged."""

from __future__ import annotations

import copy
import time
from typing import TYPE_CHECKING, Any

from harness.judge.answers import Answers
from harness.links.board_idle import (
    IDLE_LAST_ANSWER_S,
    IdleStreamEnd,
    set_aside_answers_to_the_idle_stream,
)
from harness.links.board_pairing import AnswerWindow, owed_answers, pair_with_driver_scans
from harness.links.bounds import POLL_S
from harness.links.node_exchange import NodeExchange, ScanDelivery

if TYPE_CHECKING:
    from harness.devices.profiles import DeviceProfile
    from harness.faults.link import LineDamage
    from harness.lidar.scan import Scan
    from harness.links.board_session import BoardSession
    from harness.ros.observer import Heard, Observer
    from harness.serial_line.server import DeviceServer

SCAN_CATCH_UP_S = 0.05  # a driver scan published before its answer reaches us within this
LATE_SCAN_WAIT_S = 0.2  # after a lost revolution: how long a second driver scan may follow
LOST_IN_A_ROW = 5  # line faults: this many revolutions without a driver scan is a failure
# A driver may skip a revolution with this few returns: rplidar's iter_scans
# (the FOSSBot v2's agent) yields none of 5 or fewer.
SPARSE_RETURNS = 5
SPARSE_WAIT_S = 0.25  # at least this long for the board's scan of such a revolution


class BoardDelivery(ScanDelivery):
    """Push each scan as a revolution to the device; pair the answers with its driver scans."""

    # A revolution the node did not answer in time never reached it (its subscription
    # was still matching), and the device must not be kept waiting while the node
    # answers nothing: the driver gives up on a silent line. Idle revolutions came
    # before the copies, and the node answers in order, so the last answer is the last
    # copy's (`collected` keeps it, setting aside what answered the idle stream).
    copies_queue = False

    def __init__(self, exchange: NodeExchange, profile: DeviceProfile) -> None:
        self.exchange, self.profile = exchange, profile
        self.session: BoardSession | None = None  # the run's (or the link's own), once open
        self.idle = IdleStreamEnd(exchange, self._damage_from_now)
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

    @property
    def _obs(self) -> Observer | None:
        return self.exchange.graph.observer

    @property
    def _server(self) -> DeviceServer:
        server = self.session.server if self.session is not None else None
        assert server is not None, "open() the link first"
        return server

    def damage_line(self, damage: LineDamage) -> None:
        """Line faults: revolutions reach the driver damaged from the next push on (never the
        idle stream); one the driver then makes no scan of is lost, not a broken link."""
        self._line_damage = damage
        if self.idle.pushed:
            self._server.damage = damage

    def _damage_from_now(self) -> None:
        """The idle stream is over: line damage acts from then on."""
        if self._line_damage is not None:
            self._server.damage = self._line_damage

    def _idle_over(self, rate: float) -> None:
        assert self.session is not None
        self.idle.over(self.session, rate)

    # -- the exchange's hooks -------------------------------------------------
    def before_first(self, scan: Scan) -> None:
        """Once the node has answered what the device streamed while it came up (those
        answers are not judged), the first scan goes out."""
        assert self.session is not None
        self.idle.end(self.session, self._rate(scan))
        self._after_idle = True

    def after_first(self) -> None:
        """As after a warm-up, the stream ends on a whole start marker, so the later
        revolutions are the same bytes however many copies of the first it took."""
        self._after_copies()
        self._server.align_stream()

    def after_warm_up(self) -> None:
        """The stream ends on a whole start marker, so the scenario's revolutions are the
        same bytes however many warm-up pushes it took."""
        self._server.align_stream()

    def unanswerable(self) -> Answers | None:
        """The node never got this revolution: nothing to wait for (what it publishes meanwhile
        the next exchange sorts by send time)."""
        if self._lost is not None:
            if self.session is not None:
                self.session.last_tick_at = time.perf_counter()
            return Answers(lost=self._lost)
        self._heard_scans = []
        return None

    def sorted(self, answers: Answers, heard: list[Heard]) -> None:
        """Keep the driver's scans of this exchange, in order, for pairing, and when the
        device's first repeat came; set aside what answers earlier scans."""
        self._heard_scans = self._driver_scans()  # `heard` is the inbox they are read from
        self._repeat_at = self._repeat_from()
        if self._owed:  # the first statuses answer scans before this tick's (owed_answers)
            answers.keep_only(sorted(answers.statuses, key=lambda r: r.source_ns)[self._owed :])
        statuses = self._statuses()
        after = sum(1 for h in heard if h.kind == "scan" and h.source_ns > self._scans_from)
        # Owed answers that never came (a node that skips a repeat) are not carried on.
        plain = self._line_damage is None and self.exchange.copies == 1
        plain = plain and not (self._owed and answers.timed_out)
        self._window = AnswerWindow(1 + after, max(0, statuses - self._owed)) if plain else None

    def collected(self, answers: Answers) -> Answers:
        """Each answer with the driver scan it answered; answers the repeats and the idle stream
        drew answer no tick."""
        if self._after_idle:
            self._after_idle = False
            set_aside_answers_to_the_idle_stream(answers, len(self._heard_scans))
            answers.owed_before = True  # its answers still to come are newer: this tick's
        pair_with_driver_scans(answers, self._heard_scans)
        if self._repeat_at is not None:  # answers to the device's repeats answer no tick
            answers.first_answer_only()
            self.exchange.sends = [*self.exchange.sends, (None, self._repeat_at)]
        if answers.seen is None:
            answers.seen = self._seen
        answers.lost = self._lost
        if self._delivery_problem and answers.problem is None:
            answers.problem = self._delivery_problem
        if self.session is not None:
            self.session.last_tick_at = time.perf_counter()
        return answers

    def deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        """Send the revolution down the line; wait (bounded) for the driver's /scan of it."""
        assert self._obs is not None
        obs = self._obs
        obs.publish_clock(scan.stamp if clock is None else clock)
        rate = self._rate(scan)
        samples = self.profile.revolution(
            self.session.device, scan, rate, scan.range_max, mount=self.session.mount
        )
        returns = sum(1 for sample in samples if sample.distance_mm > 0)
        self._seen, self._delivery_problem, self._lost = None, None, None
        window, self._window, self._owed = self._window, None, 0
        if not self.idle.pushed:  # this scenario's first revolution: the idle stream ends
            self._idle_over(rate)
        written_ns = self._push(samples, tick, rate)
        if written_ns is None:
            return time.time_ns()

        def driver_scan() -> Any:
            return next(
                (h for h in obs.inbox if h.kind == "scan" and h.source_ns >= written_ns), None
            )

        opts = self.exchange.options
        wait = max(opts.scan_timeout, 1.0 / rate)
        sparse = returns <= SPARSE_RETURNS
        if sparse:  # the board may never publish it: do not wait a whole deadline
            skips = self.session.skips_sparse
            wait = 0.0 if skips else min(wait, max(2.0 / rate, SPARSE_WAIT_S))
        deadline = time.perf_counter() + wait
        while (heard := driver_scan()) is None:
            gone = self.exchange.graph.node_gone()
            if gone or time.perf_counter() >= deadline:
                if not gone and sparse:
                    # A board that skipped one such turn is taken to skip them all: the
                    # next are not waited for (a scan that comes after all is told
                    # apart by time, and not judged).
                    self.session.skips_sparse = True
                    self._lost = (
                        f"the board published no {opts.scan_topic} of this revolution: "
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
            self.exchange.wait_for(lambda: len(self._driver_scans()) >= 2, LATE_SCAN_WAIT_S)
        self._lost_in_a_row = 0
        return heard.source_ns

    def copy(self, n: int) -> None:
        """Each later copy of the first scan is damaged from the line's state before the first
        copy (a scratch copy of it, the stream aligned so its bytes are the first's), and once
        the copies are out the line goes on from its state after the first (`_after_copies`):
        nothing the driver sees or the line counts depends on how many copies it took."""
        if self._line_damage is None:
            return
        if n == 0:
            self._first_damage = copy.deepcopy(self._line_damage)
            return
        if n == 1:
            self._after_first = self._line_damage
        self._server.align_stream()  # the copy's bytes are the first's
        if self._first_damage is not None:
            self._server.damage = copy.deepcopy(self._first_damage)

    def _after_copies(self) -> None:
        if self._after_first is not None:
            self._line_damage, self._after_first = self._after_first, None
            self._server.damage = self._line_damage

    def _rate(self, scan: Scan) -> float:
        return 1.0 / scan.scan_time if scan.scan_time > 0 else self.exchange.options.scan_rate_hz

    def reached_node(self) -> bool:
        return self._lost is None  # a revolution the board published no scan of: lost

    def _push(self, samples: list[Any], tick: int, rate: float) -> int | None:
        """Queue the revolution and wait (bounded) until it went out whole; the system time
        before its last write, or None (why: `_delivery_problem`). A device the driver stopped
        (a driver restarting: STOP, RESET, ... SCAN) is waited for as long as a board may take
        to come up, and the revolution goes again once it scans."""
        assert self._obs is not None
        server, period = self._server, 1.0 / rate
        push = server.send_revolution(samples, tick, period)
        limit = self.exchange.options.scan_timeout + (
            3 * period if server.mode == "realtime" else 0.0
        )
        deadline = time.perf_counter() + limit
        while (delivery := server.delivery_of(push)) is None:
            gone = self.exchange.graph.node_gone()
            if gone is not None:
                self._delivery_problem = gone
                return None
            if not self.profile.streams_unasked and self.session.device.mode == "idle":
                if not server.wait_until(
                    lambda d: d.mode != "idle", self.exchange.options.ready_timeout
                ):
                    self._delivery_problem = (
                        f"the device stopped scanning and the board's driver did not ask "
                        f"again within {self.exchange.options.ready_timeout:g} s (on the line: "
                        f"{self.session.line_diagnosis().text()})"
                    )
                    return None
                push = server.send_revolution(samples, tick, period)
                deadline = time.perf_counter() + limit
            elif time.perf_counter() >= deadline:
                self._delivery_problem = (
                    f"the device could not send this revolution within {limit:.2f} s "
                    f"(on the line: {self.session.line_diagnosis().text()})"
                )
                return None
            self._obs.spin(POLL_S / 5)
        return delivery.written_ns

    def _no_driver_scan(self, gone: str | None) -> int:
        """No driver scan of the revolution in time: lost on a damaged line, else a failure."""
        topic = self.exchange.options.scan_topic
        missing = f"the board's driver published no {topic} for this revolution in time"
        self._lost_in_a_row += 1
        if not gone and self._line_damage is not None:
            if self._lost_in_a_row < LOST_IN_A_ROW:
                self._lost = f"{missing} (damaged on the line)"
                return time.time_ns()
            missing = (
                f"the board's driver published no {topic} for "
                f"{self._lost_in_a_row} revolutions in a row (line faults lose some, "
                "not all)"
            )
        if not gone and self.session.physical:
            missing += f" (on the line: {self.session.line_diagnosis().text()})"
        self._delivery_problem = gone or missing
        return time.time_ns()

    def _not_this_revolution(self, written_ns: int) -> int:
        """How many driver scans of revolutions the device sent on its own (a repeat while the
        harness was late) came before this one's: their answers answer no tick."""
        assert self._obs is not None
        others = sorted(
            h.source_ns
            for h in self._obs.inbox
            if h.kind == "scan" and self._scans_from < h.source_ns < written_ns
        )
        self.exchange.sends = [*self.exchange.sends, *((None, ns) for ns in others)]
        return len(others)

    def _driver_scans(self) -> list[Heard]:
        """The driver's scans of this exchange, oldest first: its revolution's, and on a
        damaged line the ones the line made late or split (not the device's repeats)."""
        assert self._obs is not None
        since, until = self._scans_from, self._repeat_from()
        return [
            h
            for h in self._obs.inbox
            if h.kind == "scan" and since <= h.source_ns and (until is None or h.source_ns < until)
        ]

    def _repeat_from(self) -> int | None:
        """When the first scan of a revolution the device repeated on its own came (the harness
        slower than a revolution: real time), or None; the node answers in order, so its
        first answer is this tick's. With line faults a later scan may be this one split or
        made late instead."""
        if self._line_damage is not None or self._obs is None:
            return None
        since = self._scans_from
        later = [h.source_ns for h in self._obs.inbox if h.kind == "scan" and h.source_ns > since]
        return min(later) if later else None

    def _statuses(self) -> int:
        assert self._obs is not None
        return self._obs.statuses_since(self.exchange.sent_ns)

    def answered(self) -> bool:
        """One status for each driver scan this exchange brought (usually one)."""
        return self._statuses() >= max(len(self._driver_scans()), 1) + self._owed

    def settle_answers(self) -> None:
        """The first tick, while the node may still owe answers to idle revolutions: wait
        (bounded) until it has been quiet for three revolutions, so its answer to this tick,
        after those, is in (`collect` keeps the last). Line faults: more statuses than driver
        scans may mean a late scan's answer overtook the scan (two topics, two readers): wait
        a moment for it."""
        if self._after_idle and (self.idle.owed or self.exchange.copies > 1):
            # A copy went unanswered: the node was behind, and still answers the idle
            # stream's scans and the copies, in order, after the first status came.
            self.exchange.wait_for(self.idle.statuses_quiet, IDLE_LAST_ANSWER_S)
        if self._line_damage is not None and self._statuses() > len(self._driver_scans()):
            self.exchange.wait_for(
                lambda: len(self._driver_scans()) >= self._statuses(), SCAN_CATCH_UP_S
            )

    def settled(self) -> None:
        """The device may repeat its last revolution while the trailing answers are awaited:
        answers to those repeats answer no tick, never the last tick twice."""
        repeat = self._repeat_from()
        if repeat is not None:
            self.exchange.sends = [*self.exchange.sends, (None, repeat)]
