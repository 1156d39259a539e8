"""Drive one scenario: simulate, emit scans with faults, exchange, judge.

The same engine serves the CLI, the pytest plugin and CI; only the link
differs. Lockstep by default: scan k+1 is sent only after scan k's answers
arrived or its deadline passed.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from harness.answers import Answers, Received
from harness.errors import ConfigError, Interrupted, LinkError
from harness.faults import FaultProfile, build_profile
from harness.link_faults import (
    NO_LINK_FAULTS,
    Delivery,
    LineDamage,
    LinkFaults,
    plan_deliveries,
    scan_periods,
)
from harness.link_pipeline import LinkPipeline
from harness.links.base import Link, LinkOptions, create_link, link_class
from harness.node_forkserver import scope as fork_servers
from harness.oracle import Oracle
from harness.scan import Scan
from harness.scenario import Scenario, check_run_length, threshold_problem
from harness.trace import RunResult, TickRecord

if TYPE_CHECKING:
    from harness.lidar_spec import LidarSpec
    from harness.sim.simulation import SimTick


@dataclass(frozen=True)
class RunSettings:
    """Per-run overrides of what the scenario file says (None keeps the file's value)."""

    seed: int | None = None
    threshold: float | None = None
    faults: Sequence[str | dict[str, Any]] | None = None
    status_pattern: str | None = None
    gui: bool = False


def effective_threshold(scenario: Scenario, settings: RunSettings) -> float:
    """The run's threshold (the scenario's unless overridden), within the LIDAR's range."""
    if settings.threshold is None:
        return scenario.threshold
    problem = threshold_problem(settings.threshold, scenario)
    if problem is not None:
        raise ConfigError(f"threshold for scenario {scenario.name}: {problem}")
    return settings.threshold


def check_settings(scenarios: Sequence[Scenario], settings: RunSettings) -> None:
    """Every override fits every scenario: checked before the first one runs, so a
    usage error never comes after some scenarios were judged."""
    for scenario in scenarios:
        effective_threshold(scenario, settings)
        fault_profile(scenario, settings)


def fault_profile(scenario: Scenario, settings: RunSettings) -> FaultProfile:
    """The scenario's fault profile, or the run's override; errors name the file."""

    items = settings.faults if settings.faults is not None else scenario.faults
    try:
        profile = build_profile(items)
        if settings.faults is not None:  # a faster drifting rate may make the run too long
            check_run_length(scenario, profile)
        return profile
    except ConfigError as err:
        raise ConfigError(f"{_faults_origin(scenario, settings)}: {err}") from None


def _faults_origin(scenario: Scenario, settings: RunSettings) -> str:
    """Where the run's faults were named, for error messages."""
    return "--faults" if settings.faults is not None else scenario.source


@dataclass(frozen=True)
class Frame:
    """One scan to deliver, and where the robot was when it was taken."""

    tick: int
    t: float  # seconds since the start of the run (simulated or recorded)
    x: float
    y: float
    yaw: float
    scan: Scan


def run_scenario(
    scenario: Scenario,
    link: Link,
    settings: RunSettings = RunSettings(),
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
) -> RunResult:
    """Run `scenario` through an already opened `link` and judge every tick."""
    from harness.sim.simulation import Simulation  # imports pybullet

    started = time.perf_counter()
    seed = settings.seed if settings.seed is not None else scenario.seed
    threshold = effective_threshold(scenario, settings)
    profile = fault_profile(scenario, settings)
    oracle = Oracle(
        threshold, noise_sigma=profile.noise_sigma, status_pattern=settings.status_pattern
    )
    rng = np.random.default_rng(seed)
    result = RunResult(
        scenario=scenario.name,
        link=link.name,
        seed=seed,
        threshold=threshold,
        faults=profile.name,
        noise_sigma=profile.noise_sigma,
    )
    try:
        check_link_faults(profile.link, link)
    except ConfigError as err:
        raise ConfigError(f"{_faults_origin(scenario, settings)}: {err}") from None
    drift = profile.link.get("rate_drift")
    periods = scan_periods(drift, scenario.lidar_spec.rate_hz, seed) if drift else None
    try:
        with Simulation(scenario, gui=settings.gui) as sim:
            frames = (
                Frame(s.tick, s.t, s.x, s.y, s.yaw, _emit(profile, s, sim.spec, rng, bool(drift)))
                for s in sim.ticks(periods)
            )
            judge_frames(frames, link, oracle, result, on_tick=on_tick, link_faults=profile.link)
    finally:  # an interrupted run reports its time too
        result.wall_s = time.perf_counter() - started
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


def check_link_faults(faults: LinkFaults, link: Link) -> None:
    """Refuse link faults this link cannot carry (before any scan is sent)."""
    if faults.on_line and not link.serial_line:
        kinds = ", ".join(f.kind for f in faults.items if f.kind.startswith("line_"))
        raise ConfigError(
            f"faults {kinds}: need a serial link (rplidar or ldlidar), not {link.name!r}"
        )
    if faults.stale_stamps and link.serial_line:
        raise ConfigError(
            f"faults stale_stamps: on the {link.name!r} link the board's driver stamps the "
            "scans, not the harness"
        )


def judge_frames(
    frames: Iterable[Frame],
    link: Link,
    oracle: Oracle,
    result: RunResult,
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
    link_faults: LinkFaults = NO_LINK_FAULTS,
    diagnose: bool = True,
) -> RunResult:
    """Deliver each frame's scan through an opened `link`; judge and record every tick.

    Simulated runs and replayed recordings share this loop, so both are
    judged the same way. `link_faults` decide how each scan travels (late,
    dropped, twice, out of order, stale); the oracle is told, so a dropped
    scan expects no answer and a late one is timed from when it went out.
    With `diagnose`, the link's diagnostics end the run (which stops a node
    process); without, the link stays usable for another run.
    """
    # A tick waits in `pending` until the next scan's exchange is over:
    # answers to scan k that arrive after scan k+1 was sent (a Bool published
    # after the String, a second String) still count for scan k. Its answers
    # then complete, it moves to `ready` and is judged while the node works
    # on the scan after (the script never depends on verdicts, so lockstep is
    # unchanged and the oracle's time is off the round trip).
    pending: list[tuple[Frame, Answers, Delivery]] = []  # frames carry the scans as sent
    ready: list[tuple[Frame, Answers, Delivery]] = []

    def judge(frame: Frame, answers: Answers, delivery: Delivery) -> None:
        # Judge against what the node saw: over a serial link that is the
        # board driver's scan, quantised and re-binned, not ours.
        seen = answers.seen if answers.seen is not None else frame.scan
        verdict = oracle.judge(frame.tick, frame.t, seen, answers, delivery)
        # Judged whole; kept clipped (lengths noted), so a flood cannot bloat the reports.
        record = TickRecord(
            frame.tick,
            frame.t,
            frame.x,
            frame.y,
            frame.yaw,
            frame.scan,
            answers.clipped(),
            verdict.clipped(),
            delivery,
        )
        result.records.append(record)
        if on_tick is not None:
            on_tick(record)

    def judge_ready() -> None:
        for held in ready:
            judge(*held)
        ready.clear()

    def complete_pending(late: list[Received]) -> list[Received]:
        """Give the pending ticks their late answers; they are ready to judge."""
        for frame, answers, delivery in pending:
            if delivery.delivered:
                late = answers.take_late(late, frame.tick)
        ready.extend(pending)
        pending.clear()
        return late

    warmed = False
    planned = iter(plan_deliveries(frames, link_faults, result.seed))
    current: Frame | None = None  # the frame being delivered, for an interruption's message
    try:
        upcoming = next(planned, None)
        while upcoming is not None:
            frame, delivery = upcoming
            current = frame
            if not delivery.delivered:
                pending.append((frame, Answers(), delivery))
                upcoming = next(planned, None)
                continue
            scan = frame.scan
            if delivery.stamp_age_s:
                scan = replace(scan, stamp=max(0.0, frame.t - delivery.stamp_age_s))
            try:
                if not warmed:
                    link.warm_up(frame.scan)
                    warmed = True
                    if link_faults.on_line:  # after the warm-up, whose retries vary in number
                        link.damage_line(LineDamage(link_faults, result.seed))
                if delivery.delay_s:
                    link.hold(delivery.delay_s)
                link.send(scan, frame.tick, clock=frame.t)
                # While the node works on this scan, judge the ticks that are
                # complete and simulate the next one.
                judge_ready()
                upcoming = next(planned, None)
                answers = link.collect(scan, frame.tick, may_be_ignored=delivery.may_be_ignored)
            except LinkError as err:  # the line or graph broke: end here, keep what we have
                result.error = f"t={frame.t:.2f} s tick {frame.tick}: {err}"
                break
            answers.late = complete_pending(answers.late)
            pending.append((replace(frame, scan=scan), answers, delivery))
            if answers.problem is not None:  # the node died or went silent: nothing more to judge
                result.error = f"t={frame.t:.2f} s tick {frame.tick}: {answers.problem}"
                break
        complete_pending(link.settle())  # ready ticks stay ahead of the pending ones
        judge_ready()
    except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM: keep what was judged, say where
        judge_ready()  # complete ticks only; those still waiting for answers are not judged
        raise _interrupted(err, result, current) from None
    if diagnose:
        result.diagnostics = link.diagnostics()
    return result


def _interrupted(err: KeyboardInterrupt, result: RunResult, frame: Frame | None) -> Interrupted:
    """The run's partial result, ended by the signal, for the caller to report."""
    stop = Interrupted.of(err)
    where = f" at t={frame.t:.2f} s tick {frame.tick}" if frame is not None else ""
    count = len(result.records)
    result.error = (
        f"interrupted by {stop.name}{where} ({count} tick{'' if count == 1 else 's'} judged)"
    )
    return Interrupted(stop.signum, [result])


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
) -> RunResult:
    """Open `link` (waiting until it is ready) and run `body` through it; the caller closes it.

    The result says how long the run waited for the link to come up.
    """
    started = time.perf_counter()
    try:
        link.open()
        ready = time.perf_counter() - started
        result = body(link)
    except LinkError as err:
        ready = time.perf_counter() - started
        result = not_started(str(err), link.diagnostics())
        result.not_started = True
    result.startup_s = ready
    return result


def closed(result: RunResult, link: Link, waited: float) -> None:
    """The link is closed: the time waited for it, and how its stop went, join the result."""
    result.stop_s = waited
    note = link.stop_note()
    if note:
        result.diagnostics = "\n".join(part for part in (result.diagnostics, note) if part)


def scenario_options(
    scenario: Scenario, options: LinkOptions, settings: RunSettings
) -> LinkOptions:
    """The link options for one scenario: its threshold and its LIDAR's rate."""
    threshold = effective_threshold(scenario, settings)
    return replace(options, threshold=threshold, scan_rate_hz=scenario.lidar_spec.rate_hz)


def _not_started_as(
    scenario: Scenario, link_name: str, settings: RunSettings
) -> Callable[[str, str], RunResult]:
    """How a scenario whose link never came up is recorded."""
    threshold = effective_threshold(scenario, settings)
    seed = settings.seed if settings.seed is not None else scenario.seed
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
    return with_link(
        link_name,
        scenario_options(scenario, options, settings),
        lambda link: run_scenario(scenario, link, settings, on_tick=on_tick),
        _not_started_as(scenario, link_name, settings),
    )


def run_suite(
    scenarios: Sequence[Scenario],
    link_name: str,
    options: LinkOptions,
    settings: RunSettings = RunSettings(),
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
    on_result: Callable[[RunResult], None] | None = None,
) -> list[RunResult]:
    """Run each scenario in turn, each through a link of its own, and report the
    results in order.

    Where links can overlap (their own ROS domains), the next scenarios'
    links start while one runs and finished ones stop behind it
    (``harness.link_pipeline``). Once the software under test fails to come
    up, the rest are marked not run instead of each waiting out its start.
    """
    results: list[RunResult] = []

    def report(result: RunResult) -> None:
        results.append(result)
        if on_result is not None:
            on_result(result)

    def make(index: int) -> Link:
        return create_link(link_name, scenario_options(scenarios[index], options, settings))

    link_class(link_name).prepare(options)
    with fork_servers(), _explicit_domain(link_name, options):
        pipeline = LinkPipeline(make, len(scenarios), overlap=_links_overlap(link_name, options))
        failed_start: str | None = None
        index = 0
        try:
            for index, scenario in enumerate(scenarios):
                if failed_start is not None:
                    pipeline.drain()
                    reason = f"not run: the node did not start in {failed_start}"
                    report(_not_run(scenario, link_name, reason))
                    continue
                started = time.perf_counter()
                link = pipeline.take(index)  # starts it (unless started ahead), and the next ones
                taking = time.perf_counter() - started
                result = run_through(
                    link,
                    lambda link, s=scenario: run_scenario(s, link, settings, on_tick=on_tick),
                    _not_started_as(scenario, link_name, settings),
                )
                result.startup_s += taking  # starting links is start-up too
                if result.not_started:
                    failed_start = scenario.name
                pipeline.retire(link, _reporter(result, link, report))
        except KeyboardInterrupt as err:
            pipeline.drain()  # every process reaped; finished scenarios reported first
            rest = scenarios[index:]
            raise _suite_interrupted(err, results, rest, link_name, on_result) from None
        finally:  # every link closed (in order: the last results are reported here)
            pipeline.drain()
    return results


def _reporter(
    result: RunResult, link: Link, report: Callable[[RunResult], None]
) -> Callable[[float], None]:
    """Once `link` is closed: complete `result` (`closed`) and report it."""

    def on_closed(waited: float) -> None:
        closed(result, link, waited)
        report(result)

    return on_closed


def _links_overlap(link_name: str, options: LinkOptions) -> bool:
    """Start links ahead and stop them behind? Only where each has a domain of its own."""
    return link_class(link_name).starts_ahead and options.domain_id is None


def _explicit_domain(link_name: str, options: LinkOptions) -> AbstractContextManager[object]:
    """An explicit domain id held for the whole suite (each scenario's link takes it again):
    no other run slips in between two scenarios, and an id in use fails before the first."""
    if options.domain_id is None or link_name == "inprocess":
        return nullcontext()
    from harness.ros_domain import reserve_domain

    return reserve_domain(options.domain_id)


def _suite_interrupted(
    err: KeyboardInterrupt,
    done: list[RunResult],
    rest: Sequence[Scenario],
    link_name: str,
    on_result: Callable[[RunResult], None] | None,
) -> Interrupted:
    """What the suite judged before the signal: the finished scenarios, the
    interrupted one (its judged ticks, an error saying where it stopped), and
    the others not run."""
    stop = Interrupted.of(err)
    partial = list(stop.results)
    if not partial:  # interrupted before its first tick (starting the node, building the world)
        why = f"interrupted by {stop.name} before its first tick"
        partial = [RunResult(rest[0].name, link_name, 0, 0.0, "", error=why)]
    reason = f"not run: interrupted by {stop.name}"
    skipped = [_not_run(s, link_name, reason) for s in rest[1:]]
    if on_result is not None:
        for result in [*partial, *skipped]:
            on_result(result)
    return Interrupted(stop.signum, [*done, *partial, *skipped])


def _not_run(scenario: Scenario, link_name: str, reason: str) -> RunResult:
    return RunResult(scenario.name, link_name, 0, 0.0, "", error=reason, not_run=True)
