"""A process that judges the same plans again (a grading judge's next student) is given
the frames its first run simulated: the same scans, judged the same way, no world built."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from harness.judge.records import RunResult
from harness.links import LinkOptions
from harness.runner import frame_memo, scenario_run
from harness.runner.plan import plan_run
from harness.runner.planned_ticks import planned_ticks
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario

STUDENTS = Path(__file__).parent / "student_functions.py"
SCENARIO = resolve_scenario("noisy_approach")  # seeded noise: the rng's draws are kept too


@pytest.fixture
def remembered() -> Iterator[None]:
    frame_memo.remember_frames()
    try:
        yield
    finally:
        frame_memo.remember_frames(False)


def run(processor: str | None = None, **settings: object) -> RunResult:
    options = LinkOptions(processor=processor)
    return scenario_run.run(SCENARIO, "inprocess", options, RunSettings(**settings))


def ticks(result: RunResult) -> list[tuple[object, ...]]:
    return [(r.tick, r.t, r.x, r.yaw, r.scan.to_bytes(), r.verdict.ok) for r in result.records]


def test_a_plan_run_again_is_sent_the_frames_of_its_first_run(remembered: None) -> None:
    alone = ticks(run())  # kept from here on
    plan = plan_run(SCENARIO, "inprocess", LinkOptions(), RunSettings())
    kept = frame_memo.frames_of(plan)
    assert kept is not None and len(kept) == len(alone)
    assert not kept[0].scan.ranges.flags.writeable  # nothing downstream can change them
    again = run()
    assert ticks(again) == alone and again.ok
    mistaken = run(f"{STUDENTS}:angle_in_degrees")  # another node: the same scans, its verdicts
    assert [t[:5] for t in ticks(mistaken)] == [t[:5] for t in alone] and not mistaken.ok


def test_a_run_that_stops_early_keeps_every_frame_and_other_seeds_are_other_plans(
    remembered: None,
) -> None:
    stopped = run(f"{STUDENTS}:angle_in_degrees", stop_at_first_failure=True)
    plan = plan_run(SCENARIO, "inprocess", LinkOptions(), RunSettings(stop_at_first_failure=True))
    kept = frame_memo.frames_of(plan)
    assert stopped.stopped_early and kept is not None and len(kept) > len(stopped.records)
    assert ticks(run()) == ticks(run(f"{STUDENTS}:correct_other_wording"))  # its frames, whole
    first = ticks(run(seed=1))
    assert ticks(run(seed=2)) != first and ticks(run(seed=1)) == first


def test_without_remembering_nothing_is_kept() -> None:
    run()
    assert (
        frame_memo.frames_of(plan_run(SCENARIO, "inprocess", LinkOptions(), RunSettings())) is None
    )


def test_frames_a_process_saved_are_what_another_is_sent_for_the_same_scenario(
    remembered: None, tmp_path: Path
) -> None:
    """grade counts the ticks (planned_ticks) and saves the frames; a judge loads them for
    its own reading of the scenario file, and runs as if it had simulated them itself."""
    assert planned_ticks([SCENARIO], RunSettings()) == {SCENARIO.name: len(run().records)}
    saved = tmp_path / "frames.pickle"
    assert frame_memo.save_frames(saved)
    frame_memo.remember_frames(False)
    simulated = ticks(run())  # a world of its own
    frame_memo.remember_frames()  # the judge's process: nothing kept yet
    judges_own = resolve_scenario("noisy_approach")  # not the grader's object
    changed = judges_own.model_copy(update={"obstacles": []})  # edited since: no wall
    assert frame_memo.load_frames(saved, [changed]) == 0  # another scenario's frames: none
    assert frame_memo.load_frames(saved, [judges_own]) == 1
    plan = plan_run(judges_own, "inprocess", LinkOptions(), RunSettings())
    given = frame_memo.frames_of(plan)
    assert given is not None and not given[0].scan.ranges.flags.writeable
    sent = scenario_run.run(judges_own, "inprocess", LinkOptions(), RunSettings())
    assert ticks(sent) == simulated
    assert frame_memo.load_frames(tmp_path / "missing.pickle", [judges_own]) == 0
