"""A right node whose status is JSON, a printed dict or YAML-like lines passes the
default suite: in process for each format, and over ROS 2 (tests/ros/)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.judge.records import RunResult
from harness.links import LinkOptions
from harness.runner import scenario_run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario, shipped_scenarios

FUNCTIONS = Path(__file__).parent / "structured_functions.py"
SHIPPED = [s.name for s in shipped_scenarios()]


def run(name: str, processor: str) -> RunResult:
    scenario = resolve_scenario(name)
    settings = RunSettings()
    return scenario_run.run(scenario, "inprocess", LinkOptions(processor=processor), settings)


@pytest.mark.parametrize("fn", ["json_with_infinity", "printed_dict", "yaml_lines"])
def test_structured_status_passes_the_default_suite(fn: str) -> None:
    """Every shipped scenario, out_of_range and drive_past_10m (nothing in range) included."""
    assert {"out_of_range", "drive_past_10m"} <= set(SHIPPED)
    for name in SHIPPED:
        result = run(name, f"{FUNCTIONS}:{fn}")
        assert result.ok, result.first_failure
