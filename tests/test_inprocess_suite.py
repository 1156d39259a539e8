"""The shipped scenarios end to end through the inprocess link (no ROS)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from harness.judge.records import RunResult
from harness.links import LinkOptions
from harness.runner import scenario_run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario, shipped_scenarios

STUDENTS = Path(__file__).parent / "student_functions.py"

SHIPPED = [s.name for s in shipped_scenarios()]


def run(name: str, processor: str | None = None, **settings) -> RunResult:
    scenario = resolve_scenario(name)
    run_settings = RunSettings(**settings)
    return scenario_run.run(scenario, "inprocess", LinkOptions(processor=processor), run_settings)


@pytest.mark.parametrize("name", SHIPPED)
def test_reference_passes(name: str) -> None:
    """The reference solution holds every expectation of every shipped scenario."""
    result = run(name)
    assert result.ok, result.first_failure
    assert len(result.records) >= 20


@pytest.mark.parametrize("fn", ["correct_other_wording", "correct_bool_only_when_close"])
def test_correct_students_pass(fn: str) -> None:
    """Right answers in other words, or a Bool only when close, are accepted."""
    for name in SHIPPED:
        result = run(name, f"{STUDENTS}:{fn}")
        assert result.ok, result.first_failure


# Each bug and the shipped scenario that must catch it (others may too).
BUGS = {
    "min_over_raw_ranges": "drive_past_10m",
    "no_range_min_filter": "out_of_range",
    "angle_without_angle_min": "rotate_beside_wall",
    "angle_in_degrees": "rotate_beside_wall",
    "crash_when_nothing_in_range": "drive_past_10m",
    "no_bool": "approach_wall",
    "inverted_bool": "approach_wall",
    "threshold_hard_coded": "obstacle_at_side",
    "off_by_one_index": "rotate_beside_wall",
}


@pytest.mark.parametrize(("fn", "scenario"), BUGS.items())
def test_bug_is_caught_with_explanation(fn: str, scenario: str) -> None:
    """A buggy function fails its scenario, and the explanation names scenario and tick."""
    result = run(scenario, f"{STUDENTS}:{fn}")
    assert not result.ok
    first = result.first_failure
    assert first is not None and first.startswith(f"{scenario}: t=")
    assert " tick " in first and "expected" in first


def test_bugs_caught_by_lab_scenarios() -> None:
    """The three lab scenarios alone catch the pitfalls the lab warns about."""
    for fn in ("min_over_raw_ranges", "crash_when_nothing_in_range", "no_bool", "inverted_bool"):
        results = [
            run(s, f"{STUDENTS}:{fn}") for s in ("approach_wall", "drive_past_10m", "out_of_range")
        ]
        assert not all(r.ok for r in results), fn


def test_same_seed_gives_byte_identical_scans_and_verdicts() -> None:
    """Determinism: two runs of a noisy scenario emit the same bytes and verdicts."""
    a, b = run("noisy_approach"), run("noisy_approach")
    assert [r.scan.to_bytes() for r in a.records] == [r.scan.to_bytes() for r in b.records]
    assert [r.verdict.ok for r in a.records] == [r.verdict.ok for r in b.records]


def test_other_seed_gives_other_noise() -> None:
    """The seed really drives the faults."""
    a, b = run("noisy_approach"), run("noisy_approach", seed=99)
    assert a.records[0].scan.to_bytes() != b.records[0].scan.to_bytes()


def test_processor_crash_is_a_verdict() -> None:
    """An exception in the processing function ends the run with its message, not a traceback."""
    result = run("drive_past_10m", f"{STUDENTS}:crash_when_nothing_in_range")
    assert result.error is not None and "ValueError" in result.error


def test_a_hard_coded_threshold_is_named_with_the_threshold_it_behaves_as() -> None:
    """The harness passes 0.3 m; the function warns below 0.5 m: the whole run says so."""
    result = run("obstacle_at_side", f"{STUDENTS}:threshold_hard_coded", threshold=0.3)
    first = result.first_failure or ""
    assert "expected warning False (or none); got True" in first
    assert "the node warns as if its threshold were between 0.4" in first
    assert "not the 0.3 m the harness passed" in first


@pytest.mark.parametrize("fn", ["inverted_bool", "no_bool", "angle_in_degrees"])
def test_other_bugs_get_no_threshold_hint(fn: str) -> None:
    """An inverted Bool fits no threshold; missing Bools and wrong angles are not about it."""
    results = [run(name, f"{STUDENTS}:{fn}") for name in ("approach_wall", "rotate_beside_wall")]
    assert not all(r.ok for r in results)
    assert all("as if its threshold" not in (r.first_failure or "") for r in results)


def test_a_suite_opens_each_link_once_its_world_is_built(monkeypatch) -> None:
    """A node still coming up does so while the scenario's world is built: the link is
    opened inside the world, and the wait for it counts as start-up, not as the run."""
    from harness.links.base import LinkOptions as Options
    from harness.links.inprocess import InprocessLink
    from harness.runner.suite import run_suite
    from harness.sim.simulation import Simulation

    events: list[str] = []
    entered, opened = Simulation.__enter__, InprocessLink.open

    def enter(self):
        events.append("world")
        return entered(self)

    def slow_open(self):
        events.append("open")
        time.sleep(0.2)  # a node that takes its time to come up
        opened(self)

    monkeypatch.setattr(Simulation, "__enter__", enter)
    monkeypatch.setattr(InprocessLink, "open", slow_open)
    scenarios = [resolve_scenario(n) for n in ("approach_wall", "out_of_range")]
    results = run_suite(scenarios, "inprocess", Options())
    assert events == ["world", "open", "world", "open"]
    assert all(r.ok for r in results), [r.first_failure for r in results]
    assert all(r.startup_s >= 0.2 for r in results)
