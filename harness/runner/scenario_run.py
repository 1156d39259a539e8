"""One scenario: simulated, spoiled by its faults and judged through a link.

The same engine serves the CLI, the pytest plugin and CI; only the link
differs.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from harness.errors import ConfigError, LinkError, NeverReady
from harness.faults.sensor import FaultProfile
from harness.judge.records import RunResult, TickRecord
from harness.lidar.mount import FORWARD
from harness.lidar.scan import Scan
from harness.links.base import Link, LinkOptions, create_link
from harness.runner.frame_memo import complete, frames_of, keeping
from harness.runner.frames import Frame, check_link_faults, judge_frames
from harness.runner.plan import RunPlan, plan_run
from harness.runner.settings import RunSettings, faults_origin
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.lidar.spec import LidarSpec
    from harness.sim.simulation import SimTick


def run_scenario(
    plan: RunPlan,
    link: Link,
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
) -> RunResult:
    """Run the planned scenario through `link` and judge every tick.

    The link is opened here once the world is built (or the frames of an earlier
    run of the plan here are at hand, harness.runner.frame_memo): a node still
    coming up (started ahead, or by `start`) does so meanwhile. Its wait is the
    result's `startup_s`; a LinkError from the open propagates (`run_through`).
    """
    started = time.perf_counter()
    scenario, profile, settings = plan.scenario, plan.profile, plan.settings
    result = plan.result()
    try:
        check_link_faults(profile.link, link)
    except ConfigError as err:
        raise ConfigError(f"{faults_origin(scenario, settings)}: {err}") from None

    def judge(frames: Iterable[Frame]) -> None:
        opening = time.perf_counter()
        link.open()
        result.startup_s = time.perf_counter() - opening
        judge_frames(
            frames,
            link,
            plan.oracle(),
            result,
            on_tick=on_tick,
            link_faults=profile.link,
            stop_at_first_failure=settings.stop_at_first_failure,
        )

    try:
        kept = frames_of(plan)
        if kept is not None:  # simulated here before: the same frames, no world to build
            judge(kept)
        else:
            with simulated_frames(plan) as simulated:
                frames = keeping(plan, simulated)
                judge(frames)
                complete(frames)  # where frames are kept: those of a run that ended early too
    finally:  # an interrupted run reports its time too; waiting for the link is start-up
        result.wall_s = time.perf_counter() - started - result.startup_s
    return result


@contextlib.contextmanager
def simulated_frames(plan: RunPlan) -> Iterator[Iterator[Frame]]:
    """The plan's frames, from a world of its own built on entry (before a link is opened:
    a node started ahead comes up meanwhile) and closed on exit: the scans its faults
    spoil, drawn from the plan's seed."""
    from harness.sim.simulation import Simulation  # imports pybullet

    rng = np.random.default_rng(plan.seed)
    with Simulation(plan.scenario, gui=plan.settings.gui) as sim:
        yield (
            Frame(s.tick, s.t, s.x, s.y, s.yaw, _emit(plan.profile, s, sim.spec, rng))
            for s in sim.ticks(plan.periods())
        )


def _emit(
    profile: FaultProfile,
    tick: SimTick,
    spec: LidarSpec,
    rng: np.random.Generator,
) -> Scan:
    """The scan a driver publishes for one tick; a drifting rate also sets its timing fields."""
    scan = profile.emit(tick.truth, spec, rng, stamp=tick.t)
    if profile.link.get("rate_drift") is not None:
        scan = replace(scan, scan_time=tick.period, time_increment=tick.period / spec.samples)
    return scan


def with_link(
    link_name: str,
    options: LinkOptions,
    body: Callable[[Link], RunResult],
    not_started: Callable[[str, str], RunResult],
) -> RunResult:
    """Make the named link, run `body` through it (which opens it), always close it.

    A link that cannot bring the software under test up gives
    ``not_started(reason, diagnostics)`` instead of an exception.
    """
    link = create_link(link_name, options)
    try:
        result = run_through(link, body, not_started)
    finally:
        started = time.perf_counter()
        link.close()
    closed(result, link, time.perf_counter() - started)
    return result


def run_through(
    link: Link,
    body: Callable[[Link], RunResult],
    not_started: Callable[[str, str], RunResult],
) -> RunResult:
    """Run `body` through `link`, which opens it (waiting until it is ready); the caller
    closes it. A link that cannot bring the software under test up (a LinkError) gives
    ``not_started(reason, diagnostics)``, saying how long the run waited for it."""
    started = time.perf_counter()
    try:
        return body(link)
    except LinkError as err:
        result = not_started(str(err), link.diagnostics())
        result.not_started = True
        result.never_ready = isinstance(err, NeverReady)
        result.startup_s = time.perf_counter() - started
        return result


def closed(result: RunResult, link: Link, waited: float) -> None:
    """The link is closed: the time waited for it, and how its stop went, join the result
    (and, on a serial link, the device's mount and the gap since the scenario before)."""
    result.stop_s = waited
    result.gap_s = link.gap_s
    result.node_start = link.node_start
    if link.serial_line:
        result.lidar_mount = link.options.lidar_mount or FORWARD
    note = link.stop_note()
    if note:
        result.diagnostics = "\n".join(part for part in (result.diagnostics, note) if part)


def run(
    scenario: Scenario,
    link_name: str,
    options: LinkOptions,
    settings: RunSettings = RunSettings(),
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
) -> RunResult:
    """Open the named link, run the scenario through it, always close it.

    A link that cannot bring the software under test up gives a result with
    the reason and ``not_started`` set, not an exception.
    """
    plan = plan_run(scenario, link_name, options, settings)
    return with_link(
        link_name,
        plan.options,
        lambda link: run_scenario(plan, link, on_tick=on_tick),
        plan.not_started,
    )
