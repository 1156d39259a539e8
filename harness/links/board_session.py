"""One emulated LIDAR for a whole run: the line, the device and the board's software.

A real LIDAR streams from its SCAN until its STOP, and the board's driver reads
every scenario without reconnecting (the FOSSBot v2's agent waits for bytes with no
timeout: a silent device would hang it). So a serial run has one session: the port,
one ``DeviceServer`` that never falls silent while the device scans, and on the
virtual board the board's software (the bundled driver or the user's board commands)
started before the first scenario and stopped after the last. Between scenarios the
device streams the last revolution again (``between``); each scenario's ``BoardLink``
uses the session's device and domain."""

from __future__ import annotations

import contextlib
import os
import shlex
import sys
from dataclasses import replace
from typing import TYPE_CHECKING

from harness.devices.profiles import DeviceProfile
from harness.devices.revolution import Sample
from harness.errors import ConfigError, LinkError, OptionError
from harness.lidar.mount import FORWARD, LidarMount
from harness.links.base import LinkOptions
from harness.links.bounds import lockstep_wait_s
from harness.nodes.command import NodeCommand, ros_arguments, shell_node
from harness.nodes.process import NodeProcess
from harness.option_names import named
from harness.ros.domain import DomainReservation, discovery_environment, reserve_domain

if TYPE_CHECKING:
    from harness.serial_line.diagnosis import LineReport
    from harness.serial_line.ports import DevicePort
    from harness.serial_line.server import DeviceServer

PORT_FIELD = "{port}"
DRIVER_NAME = "the board's LIDAR driver"  # the bundled driver, in messages
OWN_TOPICS = "/_fossbot_hil"  # where each node under test answers (`node_topics`)
END_IDLE_S = 1.0  # lockstep: for the idle stream's last revolution to be written
OUTPUTS = ("stderr", "stdout")


def board_command(text: str, port: str = "/dev/null") -> NodeCommand:
    """A `--board-command` item with `{port}` replaced by the device's path, checked as a
    node's command is (the program exists; ConfigError naming the item as given)."""
    try:
        argv = shell_node(
            text.replace(PORT_FIELD, shlex.quote(port)), option=named("board_commands")
        ).argv
    except ConfigError as err:
        raise ConfigError(str(err).replace(shlex.quote(port), PORT_FIELD)) from None
    return NodeCommand(argv, description=f"board command {text!r}")


def takes_remaps(command: NodeCommand) -> bool:
    """Does the node take ``--ros-args`` (so ``-r`` remaps its topics)? Not one a launch
    file starts: its items are launch arguments."""
    return command.launch_arguments is None


def remappable(*topics: str) -> bool:
    """Plain names a ``-r`` remap can move (not a private ``~`` or substituted one)."""
    return all(name and name[0] not in "~{" for name in topics)


def check_board_commands(texts: tuple[str, ...]) -> None:
    """Every `--board-command` can start (checked before anything runs: exit 2 now)."""
    for text in texts:
        board_command(text)


def board_options(options: LinkOptions) -> LinkOptions:
    """Options for a board: a physical board's own nodes, in its own domain."""
    physical = options.port is not None
    if physical and (options.node or options.package):
        raise OptionError(
            "port",
            "{port} drives a physical board, which runs its own nodes: drop {node}/{package}",
        )
    if physical and options.domain_id is None:
        # Joining a board's graph: its domain, not a reserved private one.
        env_id = os.environ.get("ROS_DOMAIN_ID", "0")
        options = replace(options, domain_id=int(env_id) if env_id.isdigit() else 0)
    return options


class BoardSession:
    """The serial line, its emulated device and the board's software, for a whole run (a
    context manager); ``options`` are the first scenario's, only the rate changes after."""

    def __init__(self, profile: DeviceProfile, options: LinkOptions) -> None:
        self.profile, self.options = profile, options
        self.physical = options.port is not None
        if self.physical and options.board_commands:
            raise OptionError(
                "board_commands",
                "{board_commands} runs the board's software on the virtual board; with {port} "
                "the physical board runs its own",
            )
        check_board_commands(options.board_commands)
        self.mount: LidarMount = options.lidar_mount or FORWARD
        self.device = profile.make_device(options.scan_rate_hz)
        # Real time on a physical line, when asked, and for the board's own software,
        # which may not be held in lockstep (a driver with its own timing or timeouts).
        own_software = bool(options.board_commands)
        self.mode = "realtime" if options.realtime or self.physical or own_software else "lockstep"
        self.port: DevicePort | None = None
        self.server: DeviceServer | None = None
        self.domain: DomainReservation | None = None
        self.processes: list[tuple[str, NodeProcess]] = []  # (name in messages, process)
        # perf_counter when the last tick's exchange ended (judged, or lost: no board scan)
        self.last_tick_at: float | None = None
        # Does the board skip revolutions with next to no returns (rplidar's iter_scans
        # does)? None until one such revolution was sent.
        self.skips_sparse: bool | None = None
        self._nodes = 0  # nodes under test given topics of their own (`node_topics`)
        self._closed = False

    # -- life cycle -------------------------------------------------------
    def open(self) -> BoardSession:
        """Reserve the run's domain, open the line, start the device and the board's software."""
        from harness.serial_line.device_line import open_device_line

        opts = self.options
        try:
            self.domain = reserve_domain(opts.domain_id)
            line = open_device_line(
                self.device,
                port=opts.port,
                baudrate=self.profile.baudrate,
                mode=self.mode,
                revolution_period_s=1.0 / opts.scan_rate_hz,
                next_start="replace",  # no driver ever sees an extra, marker-only revolution
                continuous=True,
            )
            self.port, self.server = line.port, line.server.start()
            # Until the first scenario's first frame: an empty room.
            self.server.stream_idle(self._empty_revolution(opts.scan_rate_hz))
            if not self.physical:
                self._start_board_software()
        except BaseException:
            self.close()
            raise
        return self

    def __enter__(self) -> BoardSession:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def domain_id(self) -> int:
        assert self.domain is not None, "open() the session first"
        return self.domain.domain_id

    def _environment(self) -> dict[str, str]:
        """What the board's processes get: the run's ROS domain and discovery, and the
        pty's modem lines (only a virtual board starts the board's software)."""
        from harness.serial_line.ports import PtyPort

        assert isinstance(self.port, PtyPort)
        return {
            "ROS_DOMAIN_ID": str(self.domain_id),
            **discovery_environment(network=self.options.ros_network),
            **self.port.client_environment(),
        }

    def _start_board_software(self) -> None:
        assert self.port is not None
        path = self.port.slave_path
        env = self._environment()
        assert self.domain is not None
        held = self.domain.fileno()  # each process keeps the domain while it lives
        if self.options.board_commands:
            for text in self.options.board_commands:
                command = board_command(text, path)
                self._start(command.description, NodeProcess(command, [], env, held=held))
        else:
            arguments = self._driver_arguments(path)
            driver = NodeProcess(self._driver_command(), arguments, env, held=held)
            self._start(DRIVER_NAME, driver)

    def _start(self, name: str, process: NodeProcess) -> None:
        self.processes.append((name, process))
        process.start()

    def _driver_command(self) -> NodeCommand:
        """The bundled board driver, started anew (not forked: its modem lines come from
        the interpreter's start-up, as for the board's own software)."""
        module = self.profile.driver_module
        return NodeCommand((sys.executable, "-m", module), description=f"board driver {module}")

    def _driver_arguments(self, path: str) -> list[str]:
        """The bundled driver's parameters: this device, this mount, a bounded read wait."""
        opts = self.options
        invert, offset = self.mount.driver_settings()
        # Between scenarios and while a node comes up the device keeps streaming;
        # in lockstep it pauses while the harness waits for the node (the
        # deadline, then the catch-up wait): the driver's no-data timeout
        # must outlast that.
        longest_wait = lockstep_wait_s(opts.scan_timeout)
        return ros_arguments(
            (
                f"port:={path}",
                f"scan_topic:={opts.scan_topic}",
                f"timeout:={longest_wait + 2.0!r}",
                f"invert:={'true' if invert else 'false'}",
                f"angle_offset_deg:={float(offset)!r}",
            ),
            use_sim_time=False,
        )

    def _empty_revolution(self, rate_hz: float) -> list[Sample]:
        """A revolution with no return anywhere, at the device's native sample count."""
        count = self.profile.samples_per_rev(self.device, rate_hz)
        return [Sample(360.0 * j / count, 0.0, 0) for j in range(count)]

    def node_topics(self, status: str, warning: str) -> tuple[str, str] | None:
        """A status and a warning topic of its own for the next node under test, or None for
        names that are not plain (a private ``~`` name). The next node starts while this one
        runs, both hearing the board's scans: each answers under ``OWN_TOPICS`` (hidden, as a
        leading underscore makes a name), so no answer reaches another scenario's judging."""
        if not remappable(status, warning):
            return None
        self._nodes += 1
        prefix = f"{OWN_TOPICS}/node{self._nodes}"
        return tuple(f"{prefix}/{name.lstrip('/')}" for name in (status, warning))  # type: ignore[return-value]

    # -- between and during scenarios -------------------------------------
    def set_rate(self, rate_hz: float) -> None:
        """A scenario's LIDAR rate: the device spins at it (as a real one's drifts)."""
        assert self.server is not None
        self.server.period_s = 1.0 / rate_hz
        self.device.set_rate(rate_hz)  # an LD06/LD19 reports its speed in each packet

    def between(self) -> None:
        """A scenario is over: the device keeps scanning the same world until the next one."""
        if self.server is not None and self.server.error is None and not self._closed:
            self.server.stream_idle()

    def end_idle(self) -> int | None:
        """Before a scenario's first push in lockstep: stop the idle stream. Returns the
        system time (ns) after which the driver's scan of its last revolution comes, or None."""
        assert self.server is not None
        delivery = self.server.end_idle(END_IDLE_S)
        return delivery.written_ns if delivery is not None else None

    def line_diagnosis(self) -> LineReport:
        """The serial line's story in its three parts: sent, came back, likely cause."""
        from harness.serial_line.diagnosis import diagnose

        assert self.server is not None and self.port is not None
        return diagnose(
            self.server.stats(),
            port=f"{named('port')} {self.port.name}" if self.physical else self.port.name,
            baudrate=self.profile.baudrate,
            streams_unasked=self.profile.streams_unasked,
        )

    def gone(self, when: str = "") -> str | None:
        """Why the device or the board's software stopped, or None while all run."""
        if self.server is not None and self.server.error is not None:
            return f"{self.profile.name} line: {self.server.error}"
        for name, process in self.processes:
            if process.returncode() is not None:
                return f"{name} {process.exit_summary(when)}"
        return None

    def diagnostics(self) -> str:
        """The board's software's last output, for a failure report."""
        tails = [(name, which, p.tail(which)) for name, p in self.processes for which in OUTPUTS]
        return "\n".join(
            f"{name} {which} (last lines):\n{tail}" for name, which, tail in tails if tail
        )

    def close(self) -> None:
        """Stop the board's software, the device and the line; release the domain. Twice is safe."""
        if self._closed:
            return
        self._closed = True
        for _, process in self.processes:
            process.request_stop()
        if self.server is not None:
            with contextlib.suppress(LinkError):  # already reported by the exchange that met it
                self.server.close()
        for _, process in self.processes:
            process.stop()
        if self.port is not None:
            self.port.close()
        if self.domain is not None:
            self.domain.release()

    def stop_note(self) -> str:
        """After `close`: what stopping the board's software took beyond the usual."""
        notes = [f"stopping {name}: {p.stop_note()}" for name, p in self.processes if p.stop_note()]
        return "\n".join(notes)
