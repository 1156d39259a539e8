"""Drive one scenario: simulate, emit scans with faults, exchange, judge.

The same engine serves the CLI, the pytest plugin and CI; only the link
differs. Lockstep by default: scan k+1 is sent only after scan k's answers
arrived or its deadline passed.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from harness.answers import Answers
from harness.errors import ConfigError, LinkError
from harness.faults import FaultProfile, build_profile
from harness.links.base import Link, LinkOptions, create_link
from harness.oracle import Oracle
from harness.scan import Scan
from harness.scenario import Scenario
from harness.trace import RunResult, TickRecord


@dataclass(frozen=True)
class RunSettings:
    """Per-run overrides of what the scenario file says (None keeps the file's value)."""

    seed: int | None = None
    threshold: float | None = None
    faults: Sequence[str | dict[str, Any]] | None = None
    status_pattern: str | None = None
    gui: bool = False


def effective_threshold(scenario: Scenario, settings: RunSettings) -> float:
    return settings.threshold if settings.threshold is not None else scenario.threshold


def fault_profile(scenario: Scenario, settings: RunSettings) -> FaultProfile:
    """The scenario's fault profile, or the run's override; errors name the file."""

    items = settings.faults if settings.faults is not None else scenario.faults
    try:
        return build_profile(items)
    except ConfigError as err:
        where = "--faults" if settings.faults is not None else scenario.source
        raise ConfigError(f"{where}: {err}") from None


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
    with Simulation(scenario, gui=settings.gui) as sim:
        frames = (
            Frame(s.tick, s.t, s.x, s.y, s.yaw, profile.emit(s.truth, sim.spec, rng, stamp=s.t))
            for s in sim.ticks()
        )
        judge_frames(frames, link, oracle, result, on_tick=on_tick)
    result.wall_s = time.perf_counter() - started
    return result


def judge_frames(
    frames: Iterable[Frame],
    link: Link,
    oracle: Oracle,
    result: RunResult,
    *,
    on_tick: Callable[[TickRecord], None] | None = None,
) -> RunResult:
    """Deliver each frame's scan through an opened `link`; judge and record every tick.

    Simulated runs and replayed recordings share this loop, so both are
    judged the same way.
    """
    pending: tuple[Frame, Answers] | None = None

    def judge(frame: Frame, answers: Answers) -> None:
        # Judge against what the node saw: over a serial link that is the
        # board driver's scan, quantised and re-binned, not ours.
        seen = answers.seen if answers.seen is not None else frame.scan
        verdict = oracle.judge(frame.tick, frame.t, seen, answers)
        record = TickRecord(
            frame.tick, frame.t, frame.x, frame.y, frame.yaw, frame.scan, answers, verdict
        )
        result.records.append(record)
        if on_tick is not None:
            on_tick(record)

    # Each tick is judged once the next scan's exchange is over: answers to
    # scan k that arrive after scan k+1 was sent (a Bool published after the
    # String, a second String) still count for scan k.
    for index, frame in enumerate(frames):
        if index == 0:
            link.warm_up(frame.scan)
        try:
            answers = link.exchange(frame.scan, frame.tick)
        except LinkError as err:  # the line or graph broke: end here, keep what we have
            result.error = f"t={frame.t:.2f} s tick {frame.tick}: {err}"
            break
        if pending is not None:
            answers.late = pending[1].take_late(answers.late, pending[0].tick)
            judge(*pending)
        pending = (frame, answers)
        if answers.problem is not None:  # the node died or went silent: nothing more to judge
            result.error = f"t={frame.t:.2f} s tick {frame.tick}: {answers.problem}"
            break
    if pending is not None:
        pending[1].take_late(link.settle(), pending[0].tick)
        judge(*pending)
    result.diagnostics = link.diagnostics()
    return result


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
        link.open()
        return body(link)
    except LinkError as err:
        result = not_started(str(err), link.diagnostics())
        result.not_started = True
        return result
    finally:
        link.close()


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
    threshold = effective_threshold(scenario, settings)
    rate = scenario.lidar_spec.rate_hz
    seed = settings.seed if settings.seed is not None else scenario.seed
    faults = fault_profile(scenario, settings).name

    def failed(reason: str, diagnostics: str) -> RunResult:
        return RunResult(
            scenario.name, link_name, seed, threshold, faults, error=reason, diagnostics=diagnostics
        )

    return with_link(
        link_name,
        replace(options, threshold=threshold, scan_rate_hz=rate),
        lambda link: run_scenario(scenario, link, settings, on_tick=on_tick),
        failed,
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
    """Run each scenario in turn; once the software under test fails to come
    up, the rest are marked not run instead of each waiting out its start."""
    results: list[RunResult] = []
    failed_start: str | None = None
    for scenario in scenarios:
        if failed_start is not None:
            reason = f"not run: the node did not start in {failed_start}"
            result = RunResult(scenario.name, link_name, 0, 0.0, "", error=reason, not_run=True)
        else:
            result = run(scenario, link_name, options, settings, on_tick=on_tick)
            if result.not_started:
                failed_start = scenario.name
        results.append(result)
        if on_result is not None:
            on_result(result)
    return results
