"""What a run may override (seed, threshold, faults, timeout), and its checks before any run."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from harness.errors import ConfigError
from harness.faults.sensor import FaultProfile, build_profile
from harness.option_names import named
from harness.scenario.checks import check_run_length, threshold_problem
from harness.scenario.schema import Scenario


@dataclass(frozen=True)
class RunSettings:
    """Per-run overrides of what the scenario file says (None keeps the file's value)."""

    seed: int | None = None
    threshold: float | None = None
    faults: Sequence[str | dict[str, Any]] | None = None
    status_pattern: str | None = None
    warning_when_clear: str | None = None  # "required" or "optional"; None: the scenario's
    gui: bool = False
    # End each scenario at its first failed tick (its verdict is then that tick's FAIL):
    # the audit's mutants need no more to be killed. Off for every graded run.
    stop_at_first_failure: bool = False


def effective_seed(scenario: Scenario, settings: RunSettings) -> int:
    """The run's seed: the override, else the scenario's."""
    return settings.seed if settings.seed is not None else scenario.seed


def warning_rule(scenario: Scenario, settings: RunSettings) -> str:
    """ "required" or "optional": must a node publish warning False when the way is clear?"""
    return settings.warning_when_clear or scenario.warning_when_clear


def effective_threshold(scenario: Scenario, settings: RunSettings) -> float:
    """The run's threshold (the scenario's unless overridden), within the LIDAR's range."""
    if settings.threshold is None:
        return scenario.threshold
    problem = threshold_problem(settings.threshold, scenario)
    if problem is not None:
        raise ConfigError(f"threshold for scenario {scenario.name}: {problem}")
    return settings.threshold


def check_settings(scenarios: Sequence[Scenario], settings: RunSettings) -> None:
    """Every override fits every scenario, checked before the first runs (no usage error midway)."""
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
        raise ConfigError(f"{faults_origin(scenario, settings)}: {err}") from None


def faults_origin(scenario: Scenario, settings: RunSettings) -> str:
    """Where the run's faults were named, for error messages."""
    return named("faults") if settings.faults is not None else scenario.source
