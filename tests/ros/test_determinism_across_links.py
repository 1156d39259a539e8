"""Same scenario and seed: the same scans, expectations and verdicts on every link."""

from __future__ import annotations

import pytest

from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.runner.scenario_run import run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]


def _digest(result: RunResult) -> list[tuple[int, bytes, bool, object]]:
    return [(r.tick, r.scan.to_bytes(), r.verdict.ok, r.verdict.expected) for r in result.records]


@pytest.mark.parametrize("scenario", ["noisy_approach", "out_of_range"])
def test_inprocess_and_ros2_agree_tick_by_tick(scenario: str) -> None:
    """Seeded faults draw the same noise whichever link carries the scans, and the
    reference logic judged in-process and as a node over DDS gets the same verdicts."""
    settings = RunSettings(seed=1234)
    sim = resolve_scenario(scenario)
    inprocess = run(sim, "inprocess", LinkOptions(), settings)
    ros2 = run(sim, "ros2", LinkOptions(), settings)
    assert ros2.error is None, ros2.error
    assert inprocess.ok and ros2.ok, (inprocess.first_failure, ros2.first_failure)
    assert _digest(ros2) == _digest(inprocess)
    statuses = [[a.value for a in r.answers.statuses] for r in ros2.records]
    assert statuses == [[a.value for a in r.answers.statuses] for r in inprocess.records]


def test_another_seed_gives_other_scans() -> None:
    """The seed is what makes them equal: another one draws other noise."""
    sim = resolve_scenario("noisy_approach")
    first = run(sim, "inprocess", LinkOptions(), RunSettings(seed=1))
    second = run(sim, "inprocess", LinkOptions(), RunSettings(seed=2))
    assert [r.scan.to_bytes() for r in first.records] != [r.scan.to_bytes() for r in second.records]
