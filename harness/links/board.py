"""Links through a LIDAR on a serial line: the harness plays the device.

Virtual board (default): a pty pair stands in for the USB cable, and the board's own
software (the bundled driver from node/fossbot_lidar_driver, or the board commands)
reads the emulated device and publishes /scan, which the node under test answers.
Physical board (a port named): the emulator drives a real USB-UART in real time and
the harness joins the board's ROS 2 graph. Device, line and board software live for
the run (``board_session``); a ``BoardLink`` composes the graph and the exchange with
the board delivery, and the driver's /scan of each revolution is what is judged.
A serial LIDAR's module registers its name with its device profile (``serial_lidar``)."""

from __future__ import annotations

import contextlib
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from harness.devices.profiles import DeviceProfile
from harness.errors import ConfigError
from harness.links.base import Link, LinkOptions, Part, add_link
from harness.links.board_delivery import BoardDelivery
from harness.links.board_session import BoardSession, board_options, remappable, takes_remaps
from harness.links.node_exchange import NodeExchange
from harness.links.node_graph import GraphHooks, NodeGraph
from harness.links.node_notes import WiringNotes
from harness.links.node_start import node_command
from harness.nodes.process import prepare_start
from harness.option_names import worded
from harness.ros.domain import reserve_domain

if TYPE_CHECKING:
    from harness.judge.answers import Answers
    from harness.lidar.scan import Scan


class BoardLink(Link):
    """A LIDAR device emulated on a serial line, read by the board's own driver."""

    serial_line = True
    # The board's driver publishes the scan topic for the run: the node's topics are not set.
    sets_node_topics = False
    # One line, one board; but on the virtual board the next scenario's node comes up
    # while this one runs, answering on topics of its own (`links_ahead`).
    starts_ahead = True

    def __init__(
        self,
        name: str,
        profile: DeviceProfile,
        options: LinkOptions,
        session: BoardSession | None = None,
    ) -> None:
        options = board_options(options)
        if session is not None:  # the run's device and domain
            options = replace(options, domain_id=session.domain_id)
        super().__init__(options)
        self.name = name  # type: ignore[misc]  # the serial LIDAR's (``serial_lidar``)
        self.profile = profile
        self.physical = options.port is not None
        self._own_session = session is None  # one scenario on its own: its own device
        self._gap_measured = False
        self.startup_s = 0.0
        self.command = node_command(options)  # resolve now: bad input exits 2 early
        # The node answers on status and warning topics of its own in the run's domain
        # (remapped), or on the options' (no session shared, a physical board, a launch file).
        own: tuple[str, str] | None = None
        if session is not None and not self.physical and takes_remaps(self.command):
            own = session.node_topics(options.status_topic, options.warning_topic)
        remaps: tuple[str, ...] = ()
        listen = None
        if own is not None:
            status, warning = own
            remaps = ("-r", f"{options.status_topic}:={status}")
            remaps += ("-r", f"{options.warning_topic}:={warning}")
            listen = replace(options, status_topic=status, warning_topic=warning)
        hooks = GraphHooks(
            publishes_scans=False,  # the board's driver publishes /scan; the harness listens
            runs_node=not self.physical,  # a physical board's software runs its nodes
            remaps=remaps,
            listen=listen,
            ready=self._device_asked,
            never_ready=self._never_ready,
            gone=lambda when: self.session.gone(when) if self.session is not None else None,
        )
        self.graph = NodeGraph(options, self.command, WiringNotes(options, None), hooks)
        self.node_exchange = NodeExchange(self.graph, lambda ex: BoardDelivery(ex, profile))
        self.delivery: BoardDelivery = self.node_exchange.delivery  # type: ignore[assignment]
        self.delivery.session = session

    # The session's, the graph's and the exchange's, as the runner and the tests read them.
    session = Part("delivery")
    observer = Part("graph")
    node_start = Part("graph")
    node_gone = Part("graph")
    damage_line = Part("delivery")
    warm_up = Part("node_exchange")
    send_first = Part("node_exchange")
    send = Part("node_exchange")
    hold = Part("node_exchange")
    settle = Part("node_exchange")

    @property
    def server(self) -> Any:
        return self.session.server if self.session is not None else None

    # -- processes and ports ----------------------------------------------
    def start(self) -> None:
        """Open this link's own session if it has none (a scenario run on its own); start
        the node under test (on the virtual board) and the harness's node; do not wait."""
        if self.session is None and not self.graph.started:
            try:
                self.delivery.session = BoardSession(self.profile, self.options).open()
            except Exception as err:  # raised again by open(), as a start failure
                self.graph.fail(err)
                return
            self.options = replace(self.options, domain_id=self.delivery.session.domain_id)
            self.graph.options = self.options
        self.graph.start(reserve_domain)

    def open(self) -> None:
        """Start (unless started ahead) and wait, bounded, for readiness; what was heard
        before answers nothing of this scenario's, and the device takes its rate only now
        (the scenario before may still have run at `start`)."""
        started = time.perf_counter()
        self.start()
        self.graph.open()
        self.startup_s = time.perf_counter() - started
        assert self.observer is not None and self.session is not None
        self.observer.inbox.clear()
        self.session.set_rate(self.options.scan_rate_hz)  # its turn: the device spins at its rate

    def _device_asked(self) -> bool:
        """Ready needs the driver to have asked for a scan (a device that waits to be asked)."""
        assert self.server is not None
        return self.profile.streams_unasked or self.session.device.mode != "idle"

    def _never_ready(self) -> str | None:
        """A physical board that never answers: what went down the line and came back, and why."""
        if not self.physical or self.server is None:
            return None
        assert self.session is not None
        ready = (
            f"the board never became ready within {self.options.ready_timeout:g} s "
            f"({self.profile.description})"
        )
        graph = self.observer.graph_summary() if self.observer is not None else ""
        report = self.session.line_diagnosis()
        if not report.likely or self.profile.streams_unasked:
            # Nothing wrong on the line (an LD06/LD19's line cannot tell, even after
            # streaming for a while: its driver sends nothing back): what was missing
            # is on the board's ROS 2 side.
            quiet = (
                "an LD06/LD19 driver sends nothing back, so the line cannot tell"
                if self.profile.streams_unasked
                else "the line looks right"
            )
            domain = self.graph.domain.domain_id if self.graph.domain is not None else "?"
            report = replace(
                report,
                likely=f"{quiet}; the board's nodes were not ready in ROS domain {domain}: "
                + worded(
                    "check that it is the board's ROS_DOMAIN_ID, {ros_network} (the board is "
                    "another machine), and that its LIDAR driver and node run"
                ),
            )
        line = report.text()
        return f"{ready}: on the line {line}" + (f" ({graph})" if graph else "")

    # -- the exchange -------------------------------------------------------
    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        self._between_scenarios(tick)
        return self.node_exchange.collect(scan, tick, may_be_ignored=may_be_ignored)

    def _between_scenarios(self, tick: int) -> None:
        """The first tick is out: the gap since the scenario before's last tick (``gap_s``;
        its trailing ticks the board made no scan of are its own, not the gap's)."""
        if tick < 0 or self._gap_measured or self.session is None:
            return
        self._gap_measured = True
        if self.session.last_tick_at is not None:  # a scenario ran before on this device
            self.gap_s = time.perf_counter() - self.session.last_tick_at

    # -- reporting and teardown ---------------------------------------------
    def diagnostics(self) -> str:
        parts = []
        if not self.physical and self.graph.process is not None:
            parts.append(self.graph.diagnostics(warmed_up=self.node_exchange.warmed_up))
            self.stop()
        if self.session is not None:
            parts.append(self.session.diagnostics())
        return "\n".join(p for p in parts if p)

    def notices(self) -> list[str]:
        return self.graph.notices(warmed_up=self.node_exchange.warmed_up)

    def stop(self) -> None:
        """The scenario is over: the device streams on (the run's session), the node stops."""
        if self.session is not None and not self._own_session:
            if self.server is not None:
                self.server.damage = None  # line faults are the scenario's
            self.session.between()
        self.graph.stop()

    def close(self) -> None:
        self.stop()
        self.graph.close()
        if self.session is not None and self._own_session:
            self.session.close()

    def stop_note(self) -> str:
        notes = [self.graph.stop_note()]
        if self.session is not None and self._own_session:
            notes.append(self.session.stop_note())
        return "\n".join(n for n in notes if n)


class SerialLidar:
    """A serial LIDAR's link as the registry and the runner see a link class: makes
    ``BoardLink``s with its device profile."""

    serial_line = BoardLink.serial_line
    sets_node_topics = BoardLink.sets_node_topics
    starts_ahead = BoardLink.starts_ahead

    def __init__(self, name: str, profile: DeviceProfile, module: str) -> None:
        self.name, self.profile = name, profile
        self.__module__ = module  # the link module that declares it (``kinds``' row)

    def __call__(self, options: LinkOptions, session: BoardSession | None = None) -> BoardLink:
        return BoardLink(self.name, self.profile, options, session)

    def run_session(self, options: LinkOptions) -> BoardSession:
        """One device, line and board for the whole run (see board_session)."""
        return BoardSession(self.profile, board_options(options))

    def prepare(self, options: LinkOptions) -> None:
        """Start the fork server of the virtual board's node under test."""
        if options.port is None:
            with contextlib.suppress(ConfigError):  # a bad node is reported where it is used
                prepare_start(node_command(options))

    def links_ahead(self, options: LinkOptions) -> int:
        """How many links a suite starts beyond the running one: on the virtual board the next,
        so its node is ready before this scenario's last revolution; it answers on topics of
        its own (``BoardSession.node_topics``). None on a physical board, for a launch file's
        node, or for private topic names."""
        if options.port is not None or not remappable(options.status_topic, options.warning_topic):
            return 0
        try:
            command = node_command(options)
        except ConfigError:
            return 0  # reported where the link is made
        return 1 if takes_remaps(command) else 0


def serial_lidar(name: str, profile: DeviceProfile, module: str) -> SerialLidar:
    """Register the serial LIDAR link `name` (declared in ``kinds``) for the device
    `profile`, from the link module `module`; returns it."""
    return add_link(name, SerialLidar(name, profile, module))
