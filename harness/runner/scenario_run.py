"""One scenario: simulated, spoiled by its faults and judged through a link.

The same engine serves the CLI, the pytest plugin and CI; only the link
differs.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from harness.errors import ConfigError, LinkError, NeverReady
from harness.faults.link import (
    scan_periods,
)
from harness.faults.sensor import FaultProfile
from harness.judge.records import RunResult, TickRecord
from harness.lidar.mount import FORWARD
from harness.lidar.scan import Scan
from harness.links.base import Link, LinkOptions, create_link, link_class
from harness.runner.frames import Frame, check_link_faults, judge_frames
from harness.runner.settings import (
    RunSettings,
    effective_seed,
    effective_threshold,
    fault_profile,
    faults_origin,
    judging,
)
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.lidar.spec import LidarSpec
    from harness.sim.simulation import SimTick


def run_scenario(
    scenario: Scenario,
    link: Link,
    settings: RunSettings = RunSettings(),
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
    open_link: bool = False,
) -> RunResult:
    """Run `scenario` through `link` and judge every tick.

    The link is open already, or with `open_link` it is opened here once the
    world is built: a node still coming up does so meanwhile. Its wait is the
    result's `startup_s`; a LinkError from the open propagates (`run_through`).
    """
    from harness.sim.simulation import Simulation  # imports pybullet

    started = time.perf_counter()
    profile = fault_profile(scenario, settings)
    oracle, result = judging(scenario, link.name, settings, profile)
    seed = result.seed
    rng = np.random.default_rng(seed)
    try:
        check_link_faults(profile.link, link)
    except ConfigError as err:
        raise ConfigError(f"{faults_origin(scenario, settings)}: {err}") from None
    drift = profile.link.get("rate_drift")
    periods = scan_periods(drift, scenario.lidar_spec.rate_hz, seed) if drift else None
    try:
        with Simulation(scenario, gui=settings.gui) as sim:
            if open_link:
                opening = time.perf_counter()
                link.open()
                result.startup_s = time.perf_counter() - opening
            frames = (
                Frame(s.tick, s.t, s.x, s.y, s.yaw, _emit(profile, s, sim.spec, rng, bool(drift)))
                for s in sim.ticks(periods)
            )
            judge_frames(
                frames,
                link,
                oracle,
                result,
                on_tick=on_tick,
                link_faults=profile.link,
                stop_at_first_failure=settings.stop_at_first_failure,
            )
    finally:  # an interrupted run reports its time too; waiting for the link is start-up
        result.wall_s = time.perf_counter() - started - result.startup_s
    return result


def _emit(
    profile: FaultProfile,
    tick: SimTick,
    spec: LidarSpec,
    rng: np.random.Generator,
    drifting: bool,
) -> Scan:
    """The scan a driver publishes for one tick; a drifting rate also sets its timing fields."""
    scan = profile.emit(tick.truth, spec, rng, stamp=tick.t)
    if drifting:
        scan = replace(scan, scan_time=tick.period, time_increment=tick.period / spec.samples)
    return scan


def with_link(
    link_name: str,
    options: LinkOptions,
    body: Callable[[Link], RunResult],
    not_started: Callable[[str, str], RunResult],
) -> RunResult:
    """Open the named link, run `body` through it, always close it.

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
    *,
    body_opens: bool = False,
) -> RunResult:
    """Open `link` (waiting until it is ready) and run `body` through it; the caller closes it.

    The result says how long the run waited for the link to come up. With
    `body_opens`, the body opens the link itself (``run_scenario(open_link=True)``:
    after building its world) and says how long it waited.
    """
    started = time.perf_counter()
    try:
        if not body_opens:
            link.open()
        ready = time.perf_counter() - started
        result = body(link)
    except LinkError as err:
        result = not_started(str(err), link.diagnostics())
        result.not_started = True
        result.never_ready = isinstance(err, NeverReady)
        result.startup_s = time.perf_counter() - started
        return result
    if not body_opens:
        result.startup_s = ready
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


def scenario_options(
    scenario: Scenario, options: LinkOptions, settings: RunSettings, link_name: str = ""
) -> LinkOptions:
    """The link options for one scenario: its threshold, its LIDAR's rate, whether a missed
    deadline ends it and, on a link that publishes the scans itself, the node's topics it
    names (`node_topic_options`)."""
    threshold = effective_threshold(scenario, settings)
    options = replace(
        options,
        threshold=threshold,
        scan_rate_hz=scenario.lidar_spec.rate_hz,
        late_ends_run=settings.stop_at_first_failure,
    )
    if link_name and link_class(link_name).sets_node_topics:
        options = node_topic_options(scenario, options)
    return options


def node_topic_options(scenario: Scenario, options: LinkOptions) -> LinkOptions:
    """`options` with the scenario's node_topics, each set through the node's topic
    parameter, when the run left the topics to the lab's defaults: a user who named
    topics or topic parameters of their own (a node with other names) keeps them."""
    wanted = scenario.node_topics
    if wanted is None:
        return options
    defaults = LinkOptions()
    own_topics = (options.scan_topic, options.status_topic, options.warning_topic) != (
        defaults.scan_topic,
        defaults.status_topic,
        defaults.warning_topic,
    )
    given = {item.split(":=", 1)[0] for item in options.params}
    if own_topics or given & set(options.topic_params):
        return options
    scan_param, status_param, warning_param = options.topic_params
    topics = {
        "scan_topic": (scan_param, wanted.scan),
        "status_topic": (status_param, wanted.status),
        "warning_topic": (warning_param, wanted.warning),
    }
    chosen = {field: topic for field, (_, topic) in topics.items() if topic is not None}
    params = tuple(f"{param}:={topic}" for param, topic in topics.values() if topic is not None)
    return replace(options, **chosen, params=(*options.params, *params))


def run_mount(scenarios: Sequence[Scenario], options: LinkOptions) -> LinkOptions:
    """`options` with the device's mount for the run: the option's, else what the robot
    model says. A serial link plays one device on one robot for the whole run, so the
    scenarios' models must agree (ConfigError naming the two when they do not)."""
    if options.lidar_mount is not None or not scenarios:
        return options
    from harness.scenario.mount import scenario_mount

    mounts = [(scenario_mount(s), s) for s in scenarios]
    mount, first = mounts[0]
    for other, scenario in mounts[1:]:
        if other != mount:
            raise ConfigError(
                f"{scenario.source}: its robot model mounts the LIDAR {other.describe()}, but "
                f"{first.source}'s {mount.describe()}; one device serves the whole run: "
                "run them apart, or give --lidar-mount"
            )
    return replace(options, lidar_mount=mount)


def not_started_as(
    scenario: Scenario, link_name: str, settings: RunSettings
) -> Callable[[str, str], RunResult]:
    """How a scenario whose link never came up is recorded."""
    threshold = effective_threshold(scenario, settings)
    seed = effective_seed(scenario, settings)
    faults = fault_profile(scenario, settings).name

    def failed(reason: str, diagnostics: str) -> RunResult:
        return RunResult(
            scenario.name, link_name, seed, threshold, faults, error=reason, diagnostics=diagnostics
        )

    return failed


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
    if link_class(link_name).serial_line:
        options = run_mount([scenario], options)
    return with_link(
        link_name,
        scenario_options(scenario, options, settings, link_name),
        lambda link: run_scenario(scenario, link, settings, on_tick=on_tick),
        not_started_as(scenario, link_name, settings),
    )
