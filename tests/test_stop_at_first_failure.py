"""RunSettings.stop_at_first_failure: a run ends at its first failed tick (the audit's
mutants need no more to be killed); a passing run is judged whole (in process, no ROS)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.judge.verdicts import verdict_of
from harness.links.base import LinkOptions
from harness.runner.scenario_run import run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario

pytestmark = pytest.mark.timeout(120)

STUDENTS = Path(__file__).parent / "student_functions.py"
THRESHOLD = 0.4  # threshold_hard_coded warns below 0.5 m: wrong once the wall is in between


def _run(function: str | None, stop: bool) -> object:
    processor = f"{STUDENTS}:{function}" if function else None
    settings = RunSettings(threshold=THRESHOLD, stop_at_first_failure=stop)
    return run(
        resolve_scenario("approach_wall"), "inprocess", LinkOptions(processor=processor), settings
    )


def test_a_run_with_the_setting_ends_at_its_first_failed_tick() -> None:
    """The same first failure as the whole run's, and nothing judged after it."""
    whole = _run("threshold_hard_coded", stop=False)
    first = whole.failed_ticks[0]
    assert whole.records[-1].tick > first.tick  # the whole run goes on after it
    assert not whole.stopped_early
    stopped = _run("threshold_hard_coded", stop=True)
    assert stopped.stopped_early
    assert verdict_of(stopped) == "FAIL"
    assert [r.tick for r in stopped.records] == [r.tick for r in whole.records[: first.tick + 1]]
    assert stopped.failed_ticks == [stopped.records[-1]]
    assert stopped.records[-1].verdict.explanation == first.verdict.explanation
    assert first.verdict.explanation in (stopped.first_failure or "")


def test_a_passing_run_with_the_setting_is_judged_whole() -> None:
    whole = _run(None, stop=False)
    stopped = _run(None, stop=True)
    assert verdict_of(stopped) == "PASS" and not stopped.stopped_early
    assert len(stopped.records) == len(whole.records) > 10
