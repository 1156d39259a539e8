"""Real runs to report on: the inprocess link, one passing and one failing scenario."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario

STUDENTS = Path(__file__).parents[1] / "student_functions.py"


@pytest.fixture(scope="session")
def passing() -> RunResult:
    """approach_wall against the reference logic: every tick holds."""
    [result] = run_suite([resolve_scenario("approach_wall")], "inprocess", LinkOptions())
    assert result.ok
    return result


@pytest.fixture(scope="session")
def failing() -> RunResult:
    """drive_past_10m against min(ranges): claims 'inf m' once nothing is in range."""
    processor = f"{STUDENTS}:min_over_raw_ranges"
    [result] = run_suite(
        [resolve_scenario("drive_past_10m")], "inprocess", LinkOptions(processor=processor)
    )
    assert result.failed_ticks and not result.failed_ticks[0].verdict.ok
    return result
