"""Links through a LIDAR on a serial line: the harness plays the device.

Virtual board (default): a pty pair stands in for the USB cable; the board's
own LIDAR driver node (bundled from node/fossbot_lidar_driver) reads the
emulated device and publishes /scan, and the node under test answers it,
each in its own process. Physical board (``--port``): the emulator drives a
real USB-UART wired to the board's LIDAR input in real time, and the
harness joins the board's ROS 2 graph to watch what it publishes.

Either way the lockstep machinery of the ros2 link is reused; only the
delivery differs: a scan becomes device samples, goes down the line, and the
driver's /scan for that revolution (quantised and re-binned) is what the
oracle judges, because it is what the node saw.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, ClassVar

from harness.devices.profiles import DeviceProfile
from harness.errors import ConfigError, LinkError
from harness.faults.link import LineDamage
from harness.judge.answers import Answers
from harness.lidar.scan import Scan
from harness.links.base import LinkOptions
from harness.links.ros2 import CATCH_UP_S, POLL_S, Ros2Link
from harness.nodes.command import NodeCommand, ros_arguments
from harness.nodes.process import NodeProcess, prepare_start
from harness.ros.observer import Heard

if TYPE_CHECKING:
    from harness.serial_line.diagnosis import LineReport

SCAN_CATCH_UP_S = 0.05  # a driver scan published before its answer reaches us within this
LATE_SCAN_WAIT_S = 0.2  # after a lost revolution: how long a second driver scan may follow
LOST_IN_A_ROW = 5  # line faults: this many revolutions without a driver scan is a failure
DRIVER_READY_S = 10.0  # the driver connects to the device (info, health, scan request)


class BoardLink(Ros2Link):
    """A LIDAR device emulated on a serial line, read by the board's own driver."""

    profile: ClassVar[DeviceProfile]
    serial_line = True
    publishes_scans = False  # the board's driver publishes /scan; the harness listens
    starts_ahead = False  # one line, one board at a time

    def __init__(self, options: LinkOptions) -> None:
        physical = options.port is not None
        if physical and (options.node or options.package):
            raise ConfigError(
                "--port drives a physical board, which runs its own nodes: drop --node/--package"
            )
        if physical and options.domain_id is None:
            # Joining a board's graph: its domain, not a reserved private one.
            env_id = os.environ.get("ROS_DOMAIN_ID", "0")
            options = replace(options, domain_id=int(env_id) if env_id.isdigit() else 0)
        super().__init__(options)
        self.physical = physical
        self.device = self.profile.make_device(options.scan_rate_hz)
        self.port: Any = None
        self.server: Any = None
        self.driver: NodeProcess | None = None
        self._seen: Scan | None = None
        self._delivery_problem: str | None = None
        self._lost: str | None = None  # line faults: why the driver made no scan of it
        self._scans_from = 0  # source time of the first driver scan of this revolution
        self._lost_in_a_row = 0
        self._heard_scans: list[Heard] = []
        self._line_damage: LineDamage | None = None

    # -- processes and ports ----------------------------------------------
    @classmethod
    def prepare(cls, options: LinkOptions) -> None:
        """Start the fork servers of the virtual board's driver and of the node."""
        if options.port is None:
            prepare_start(cls._driver_command())
        super().prepare(options)

    @classmethod
    def _driver_command(cls) -> NodeCommand:
        module = cls.profile.driver_module
        return NodeCommand(
            (sys.executable, "-m", module),
            description=f"board driver {module}",
            module=module,  # forked from a warm process, as the node
        )

    def _start_processes(self, env: dict[str, str]) -> None:
        from harness.serial_line.ports import PtyPort, SerialPort
        from harness.serial_line.server import DeviceServer

        opts = self.options
        if self.physical:
            assert opts.port is not None
            self.port = SerialPort(opts.port, self.profile.baudrate)
        else:
            self.port = PtyPort()
        mode = "realtime" if (opts.realtime or self.physical) else "lockstep"
        self.server = DeviceServer(
            self.device,
            self.port,
            mode=mode,
            baudrate=self.profile.baudrate,
            revolution_period_s=1.0 / opts.scan_rate_hz,
            next_start="replace",  # no driver ever sees an extra, marker-only revolution
        ).start()
        if self.physical:
            return  # the board runs its own driver and nodes
        # The emulated device is quiet until the run starts and, in lockstep,
        # while the harness waits for the node (bounded: the deadline, then
        # the catch-up wait). A real device never pauses, so the driver's
        # no-data timeout must outlast those waits and the start-up.
        longest_wait = opts.scan_timeout + max(CATCH_UP_S, 3 * opts.scan_timeout)
        read_timeout = max(longest_wait, opts.ready_timeout) + 2.0
        driver_args = ros_arguments(
            (
                f"port:={self.port.slave_path}",
                f"scan_topic:={opts.scan_topic}",
                f"timeout:={read_timeout!r}",
            ),
            use_sim_time=False,
        )
        self.driver = NodeProcess(self._driver_command(), driver_args, env)
        self.driver.start()
        super()._start_processes(env)

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
        if not report.likely:
            # Nothing wrong on the line (an LD06/LD19's line cannot tell: its driver
            # sends nothing back): what was missing is on the board's ROS 2 side.
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
        if self.server is not None and self.server.error is not None:
            return f"{self.profile.name} line: {self.server.error}"
        if self.driver is not None and self.driver.returncode() is not None:
            return f"the board's LIDAR driver {self.driver.exit_summary(when)}"
        return None if self.physical else super().node_gone(when)

    def damage_line(self, damage: LineDamage) -> None:
        """Line faults: the device's revolutions reach the driver damaged from now on.

        A revolution the driver then publishes no scan of is lost, not a
        broken link: the node had nothing to answer.
        """
        assert self.server is not None, "open() the link first"
        self.server.damage = damage
        self._line_damage = damage

    # -- delivery ---------------------------------------------------------
    def _deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        """Send the revolution down the line; wait (bounded) for the driver's /scan of it."""
        assert self.observer is not None and self.server is not None
        obs = self.observer
        obs.publish_clock(scan.stamp if clock is None else clock)
        rate = 1.0 / scan.scan_time if scan.scan_time > 0 else self.options.scan_rate_hz
        samples = self.profile.revolution(self.device, scan, rate, scan.range_max)
        pushed = time.time_ns()
        self.server.send_revolution(samples, tick, 1.0 / rate)  # real time: its own period
        self._seen, self._delivery_problem, self._lost = None, None, None

        def driver_scan() -> Any:
            return next((h for h in obs.inbox if h.kind == "scan" and h.source_ns >= pushed), None)

        deadline = time.perf_counter() + max(self.options.scan_timeout, 1.0 / rate)
        while (heard := driver_scan()) is None:
            gone = self.node_gone()
            if gone or time.perf_counter() >= deadline:
                missing = (
                    f"the board's driver published no {self.options.scan_topic} for this "
                    "revolution in time"
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
            obs.spin(min(POLL_S, deadline - time.perf_counter()))
        self._seen = heard.value
        self._scans_from = heard.source_ns
        if self._lost_in_a_row:
            # The last revolution made no scan in time: this one may be it, late (the
            # line ate what closed it), with this revolution's own scan just behind.
            self._wait_for(lambda: len(self._driver_scans()) >= 2, LATE_SCAN_WAIT_S)
        self._lost_in_a_row = 0
        return heard.source_ns

    def _driver_scans(self) -> list[Heard]:
        """The driver's scans since this revolution went down the line, oldest first."""
        assert self.observer is not None
        since = self._scans_from
        return [h for h in self.observer.inbox if h.kind == "scan" and h.source_ns >= since]

    def _statuses(self) -> int:
        assert self.observer is not None
        since = self._sent_ns
        return sum(1 for h in self.observer.inbox if h.kind == "status" and h.source_ns >= since)

    def _answered(self) -> bool:
        """One status for each driver scan this exchange brought (usually one)."""
        return self._statuses() >= max(len(self._driver_scans()), 1)

    def _settle_answers(self) -> None:
        """Line faults: more statuses than driver scans heard may mean a late scan's
        answer overtook the scan on its way to us (two topics, two readers). Wait a
        moment for it; a node that simply answers twice costs that moment."""
        if self._line_damage is not None and self._statuses() > len(self._driver_scans()):
            self._wait_for(lambda: len(self._driver_scans()) >= self._statuses(), SCAN_CATCH_UP_S)

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        if self._lost is not None:
            # The node never got this revolution: nothing to wait for. What it
            # publishes meanwhile is sorted by the next exchange, by send time.
            return Answers(lost=self._lost)
        assert self.observer is not None
        self._heard_scans = []
        answers = super().collect(scan, tick, may_be_ignored=may_be_ignored)
        _pair_with_driver_scans(answers, self._heard_scans)
        if answers.seen is None:
            answers.seen = self._seen
        answers.lost = self._lost
        if self._delivery_problem and answers.problem is None:
            answers.problem = self._delivery_problem
        return answers

    def _sort(self, answers: Answers, heard: Any, mine: Any) -> None:
        """Keep the driver's scans of this exchange, in order, for pairing."""
        self._heard_scans = self._driver_scans()  # `heard` is the inbox they are read from
        super()._sort(answers, heard, mine)

    # -- reporting and teardown ---------------------------------------------
    def diagnostics(self) -> str:
        parts = [super().diagnostics()] if not self.physical else []
        if self.driver is not None:
            for which in ("stderr", "stdout"):
                tail = self.driver.tail(which)
                if tail:
                    parts.append(f"board driver {which} (last lines):\n{tail}")
        return "\n".join(p for p in parts if p)

    def close(self) -> None:
        if self.server is not None:
            try:
                self.server.close()
            except LinkError:
                pass  # already reported by the exchange that met it
        super().close()
        if self.driver is not None:
            self.driver.stop()
        if self.port is not None:
            self.port.close()


def _pair_with_driver_scans(answers: Answers, scans: list[Heard]) -> None:
    """Give each answer the driver scan it answered.

    Usually the driver made one scan of the revolution. When the line made
    a revolution late (its scan came with the next one) or split one in
    two, several came, often published back to back, before the node
    answered any. The node answers scans in order, so the i-th status
    answers the i-th scan; a Bool goes with the status published nearest
    to it (a node publishes both in one callback). The newest scan is this
    tick's; the earlier ones go with their answers into
    ``answers.earlier``, each judged on its own.
    """
    if len(scans) < 2:
        return
    seen = [h.value for h in scans if isinstance(h.value, Scan)]
    groups = [Answers(seen=scan, waited=answers.waited) for scan in seen]
    statuses = sorted(answers.statuses, key=lambda r: r.source_ns)
    for i, item in enumerate(statuses):
        groups[min(i, len(groups) - 1)].statuses.append(item)
    for item in answers.warnings:
        if not statuses:
            groups[-1].warnings.append(item)
            continue
        nearest = min(
            range(len(statuses)), key=lambda i: abs(statuses[i].source_ns - item.source_ns)
        )
        groups[min(nearest, len(groups) - 1)].warnings.append(item)
    answers.statuses, answers.warnings = groups[-1].statuses, groups[-1].warnings
    answers.seen = seen[-1]
    answers.earlier = list(zip(seen[:-1], groups[:-1], strict=True))
