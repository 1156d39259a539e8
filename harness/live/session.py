"""One live session: the world stepped in wall-clock time, its topics, view, keyboard and judge.

The physics advances in slices of 1/60 s, each following the command in
force and publishing /clock, /odom and (at each revolution) /scan, then
waiting for its wall-clock time while it hears the node; a machine too slow
for the rate runs slower, and the summary says so. Ctrl-C ends it normally.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from harness.ctrl_c import remembered_ctrl_c
from harness.errors import ConfigError, Interrupted, LinkError, OptionError
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan
from harness.links.base import LinkOptions, create_link
from harness.links.kinds import ROS2
from harness.links.node_start import harness_observer
from harness.live.drive import CommandWatchdog
from harness.live.judge import LiveJudge
from harness.live.world import LiveWorld
from harness.ros.domain import reserve_domain
from harness.runner.plan import plan_one
from harness.runner.settings import RunSettings
from harness.scenario.schema import Scenario
from harness.sim.motion import Pose
from harness.sim.world import TIME_STEP

if TYPE_CHECKING:
    from harness.ros.observer import Observer

SCAN_FRAME = Scan.frame_id  # the frame every emitted scan carries
SLICE_STEPS = 4  # physics steps between two looks at the commands (1/60 s)
SLICE_S = SLICE_STEPS * TIME_STEP
FINAL_GRACE_S = 0.2  # wall seconds for the last scan's answers after the session ends
WARM_UP_S = 2.0  # wall seconds a node may take to answer its first scan before it is judged


@dataclass(frozen=True)
class LiveSettings:
    """How a session runs: its speed, its length, what it shows and whom it judges."""

    rate: float = 1.0  # simulated seconds per wall second
    duration: float | None = None  # simulated seconds; None: until Ctrl-C
    node: bool = False  # start the node the link options name, and judge it
    run: RunSettings = field(default_factory=RunSettings)  # seed, threshold, faults, regex


@dataclass
class LiveStats:
    """What the session reached, for the summary and the benchmarks."""

    sim_s: float = 0.0
    wall_s: float = 0.0  # the whole session, start-up included
    loop_s: float = 0.0  # wall seconds of the stepping alone
    scans: int = 0
    commands: int = 0
    late_slices: int = 0  # slices that ended after their wall-clock time
    stopped_by: str = "the duration"

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second while stepping (start-up not counted)."""
        return self.sim_s / self.loop_s if self.loop_s > 0 else 0.0


@dataclass
class LiveState:
    """What the panel and the view show: the robot and the node, now."""

    t: float = 0.0
    pose: Pose = Pose(0.0, 0.0, 0.0)
    command: tuple[float, float] = (0.0, 0.0)
    nearest: tuple[float, float] | None = None  # (m, rad) of the nearest return
    status: str | None = None
    warning: bool | None = None
    judged: int = 0
    failed: int = 0
    last_failure: str | None = None


Hook = Callable[[LiveState], None]


class LiveSession:
    """Runs one scenario's world live; `run` returns the judged result (None without a node)."""

    def __init__(
        self,
        scenario: Scenario,
        options: LinkOptions,
        settings: LiveSettings,
        *,
        on_update: Hook | None = None,
        on_ready: Callable[[int], None] | None = None,
        view: Any = None,
        keys: Any = None,
        show: Callable[[str], None] = print,
    ) -> None:
        if not settings.rate > 0 or not math.isfinite(settings.rate):
            raise OptionError.saying("rate", f"must be a positive number, got {settings.rate}")
        self.scenario = scenario
        self.settings = settings
        self.plan = plan_one(scenario, "live", options, settings.run)
        self.options, self.profile = self.plan.options, self.plan.profile
        if self.profile.link.items:
            kinds = ", ".join(f.kind for f in self.profile.link.items)
            raise ConfigError(f"faults {kinds}: link faults apply to `run`, not to a live session")
        self.on_update = on_update
        self.on_ready = on_ready  # told the ROS domain once the world runs (and the node is up)
        self.view = view  # publish_pose / publish_scan / publish_answer, or None
        self.keys = keys  # a teleop.KeyReader to drive with, or None
        self.show = show  # where the keyboard's help and speed lines go
        self.state = LiveState()
        self.stats = LiveStats()
        self.notes: list[str] = []
        self.result: RunResult | None = None
        self._external = False  # a node not started by us answers: judge it
        self._loop_started = 0.0

    def run(self) -> RunResult | None:
        """Run until the duration is reached, Ctrl-C, or the node stops; always clean up."""
        rng = np.random.default_rng(self.plan.seed)
        link: Any = None
        domain = None
        observer: Observer | None = None
        started = time.perf_counter()
        try:
            # The ros2 link starts the node, waits for it and explains what goes wrong.
            link = create_link(ROS2, self.options) if self.settings.node else None
            with LiveWorld(self.scenario) as world, remembered_ctrl_c() as ctrl_c:
                if link is not None:
                    link.open()  # the node is up and reads /scan (bounded, explained)
                    observer, domain_id = link.observer, link.domain.domain_id
                else:
                    domain = reserve_domain(self.options.domain_id)
                    domain_id = domain.domain_id
                    observer = harness_observer(self.options, domain_id, publish_scans=True)
                if self.on_ready is not None:
                    self.on_ready(domain_id)
                self._loop(world, observer, self._judge(), rng, link, ctrl_c)
        except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM while starting: a normal end too
            self.stats.stopped_by = f"{Interrupted.of(err).name} before the world ran"
        finally:
            self.stats.wall_s = time.perf_counter() - started
            if link is not None:
                link.stop()
                link.close()
            elif observer is not None:
                observer.close()
            if domain is not None:
                domain.release()
        if self.result is not None:
            self.result.wall_s = self.stats.wall_s
        return self.result

    def _judge(self) -> LiveJudge:
        """The judge, and the result it fills (dropped at the end if nothing answered)."""
        self.result = self.plan.result()
        return LiveJudge(self.plan.oracle(), self.result, on_tick=self._judged)

    def _judged(self, record: TickRecord) -> None:
        if self.view is not None:
            self.view.publish_answer(record.t, None, None, verdict=record.verdict)
        state = self.state
        state.judged += 1
        if not record.verdict.ok:
            state.failed += 1
            if record.verdict.failures:
                state.last_failure = f"t={record.t:.1f} s: {record.verdict.failures[0]}"

    def _loop(
        self,
        world: LiveWorld,
        observer: Observer,
        judge: LiveJudge,
        rng: np.random.Generator,
        link: Any,
        ctrl_c: threading.Event,
    ) -> None:
        """Step, scan and judge until the duration, Ctrl-C (`ctrl_c`: one Python may have
        swallowed) or the node's exit."""
        from harness.live.bridge import LiveBridge

        lidar_offset = _lidar_offset(world)
        bridge = LiveBridge(observer, SCAN_FRAME, lidar_offset)
        if bridge.tf_missing:
            self.notes.append(bridge.tf_missing)
        watchdog = CommandWatchdog()
        keyboard = self._keyboard(world)
        spec, rate, duration = world.spec, self.settings.rate, self.settings.duration
        # Scans fall on the physics step nearest their time (within 1/480 s).
        tick, scan_step = 0, 0
        started = self._loop_started = time.perf_counter()
        self._moved(world, bridge)
        try:
            while duration is None or world.t < duration - 1e-9:
                if ctrl_c.is_set():  # its KeyboardInterrupt was lost on the way
                    raise KeyboardInterrupt
                if world.steps >= scan_step:
                    self._scan(
                        world, observer, judge, rng, tick, judged=self._judging(observer, link)
                    )
                    tick += 1
                    scan_step = round(tick * spec.scan_time / TIME_STEP)
                else:
                    observer.publish_clock(world.t)
                self._wait_until(started + world.t / rate, observer, judge)
                _check_node(link, self.stats)
                if self.on_update is not None:
                    self.on_update(self.state)
                self._follow_commands(world, bridge, watchdog, keyboard)
                world.advance(_slice_steps(world.steps, scan_step))
                self._moved(world, bridge)
        except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM: the normal way to end
            self.stats.stopped_by = Interrupted.of(err).name
        except LinkError as err:  # the node died: the session ends, its verdicts stand
            self.stats.stopped_by = "the node's exit"
            if self.result is not None:
                self.result.error = f"t={world.t:.2f} s: {err}"
        finally:
            self.stats.sim_s = world.t
            self.stats.loop_s = time.perf_counter() - started
            self.stats.scans = tick
        self._wait_until(time.perf_counter() + FINAL_GRACE_S, observer, judge)
        judge.settle(time.time_ns(), final=True)
        if judge.unmatched:
            self.notes.append(
                f"{judge.unmatched} answers came for no scan still being judged (before the "
                "first, or after their scan was judged) and were not counted"
            )
        assert self.result is not None  # made with the judge
        if not self.result.records and link is None:
            self.result = None  # nobody answered: nothing was judged

    def _keyboard(self, world: LiveWorld) -> Any:
        """The keyboard's teleop, within the robot's limits; None without --teleop."""
        if self.keys is None:
            return None
        from harness.live.teleop import KeyboardTeleop, TeleopState

        state = TeleopState(world.limits.top_speed, world.limits.top_turn)
        teleop = KeyboardTeleop(self.keys, state, show=self.show)
        teleop.start()
        return teleop

    def _follow_commands(
        self, world: LiveWorld, bridge: Any, watchdog: CommandWatchdog, keyboard: Any
    ) -> None:
        """Drive with the newest /cmd_vel; the keyboard's go out on /cmd_vel too, as
        teleop_twist_keyboard's do, and come back like anyone else's."""
        now = time.perf_counter()
        if keyboard is not None:
            typed = keyboard.poll(now)
            if typed is not None:
                bridge.publish_command(*typed)
        for command in bridge.commands():
            watchdog.heard(command.linear, command.angular, now)
            self.stats.commands += 1
        self.state.command = world.drive(*watchdog.command(now))

    def _moved(self, world: LiveWorld, bridge: Any) -> None:
        """Tell the graph and the view where the robot is now."""
        t, pose = world.t, world.pose()
        self.state.t, self.state.pose = t, pose
        bridge.publish_odometry(t, pose, world.velocity())
        if self.view is not None:
            self.view.publish_pose(t, pose.x, pose.y, pose.yaw)

    def _scan(
        self,
        world: LiveWorld,
        observer: Observer,
        judge: LiveJudge,
        rng: np.random.Generator,
        tick: int,
        *,
        judged: bool,
    ) -> None:
        """One LIDAR revolution: cast, spoil, publish (with /clock), and hand to the judge."""
        t, pose = world.t, world.pose()
        scan = self.profile.emit(world.truth(), world.spec, rng, stamp=t)
        sent_ns = observer.publish(scan, clock=t)
        self._scanned(scan, t)
        if judged:
            judge.sent(tick, t, (pose.x, pose.y, pose.yaw), scan, sent_ns)

    def _judging(self, observer: Observer, link: Any) -> bool:
        """Judge this scan? With a node of ours, always; else once something publishes
        the status topic (a node started by hand, `ros2 launch`), from then on."""
        if link is not None:
            # As `run` warms up: from the node's first answer (a first scan can take a
            # Python node a while), or after WARM_UP_S whether it answered or not.
            answered = observer.heard["status"] > 0
            return answered or time.perf_counter() - self._loop_started > WARM_UP_S
        if self._external:
            return True
        self._external = observer.status_sub.get_publisher_count() > 0
        if self._external:
            self.notes.append(f"judging the node that publishes {self.options.status_topic}")
        return self._external

    def _scanned(self, scan: Scan, t: float) -> None:
        """The panel's nearest valid return (REP-117, as the oracle reads it); the view's scan."""
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        valid = scan.valid_mask()
        if valid.any():
            index = int(np.argmin(np.where(valid, ranges, np.inf)))
            angle = scan.angle_min + index * scan.angle_increment
            self.state.nearest = (float(ranges[index]), math.remainder(angle, 2.0 * math.pi))
        else:
            self.state.nearest = None
        if self.view is not None:
            self.view.publish_scan(t, scan)

    def _wait_until(self, deadline: float, observer: Observer, judge: LiveJudge | None) -> None:
        """Hear the node until the wall-clock `deadline`; judge what is complete."""
        late = time.perf_counter() - deadline
        if late > SLICE_S:
            self.stats.late_slices += 1
        while True:
            remaining = deadline - time.perf_counter()
            observer.spin(max(0.0, remaining))
            self._answers(observer, judge)
            if remaining <= 0:
                break
        if judge is not None:
            judge.settle(time.time_ns())

    def _answers(self, observer: Observer, judge: LiveJudge | None) -> None:
        while observer.inbox:
            heard = observer.inbox.popleft()
            if heard.kind == "status":
                self.state.status = str(heard.value)
            elif heard.kind == "warning":
                self.state.warning = bool(heard.value)
            if judge is not None and heard.kind in ("status", "warning"):
                judge.heard(heard.kind, heard.value, heard.source_ns)  # type: ignore[arg-type]
            if self.view is not None:
                status = str(heard.value) if heard.kind == "status" else None
                warning = bool(heard.value) if heard.kind == "warning" else None
                self.view.publish_answer(self.state.t, status, warning)


def _lidar_offset(world: LiveWorld) -> Pose:
    """Where the LIDAR sits on the robot: its frame relative to the base, in the plane."""
    origin, rotation = world.lidar.pose()
    base = world.pose()
    dx, dy = float(origin[0]) - base.x, float(origin[1]) - base.y
    cos, sin = math.cos(base.yaw), math.sin(base.yaw)
    yaw = math.atan2(float(rotation[1, 0]), float(rotation[0, 0])) - base.yaw
    return Pose(cos * dx + sin * dy, -sin * dx + cos * dy, math.remainder(yaw, 2.0 * math.pi))


def _slice_steps(steps: int, scan_step: int) -> int:
    """Steps in the next slice: a slice, or fewer to land on the next scan's step."""
    to_scan = scan_step - steps
    return min(SLICE_STEPS, to_scan) if to_scan > 0 else SLICE_STEPS


def _check_node(link: Any, stats: LiveStats) -> None:
    """End the session, saying how, when the node under test has exited."""
    gone = link.node_gone("during the session") if link is not None else None
    if gone is not None:
        stats.stopped_by = "the node's exit"
        raise LinkError(gone)
