"""The search and the shrinking, over landscapes whose failures are known: a rule decides
each candidate's outcome instead of a node (real optuna; the nodes' hunts are in
test_hunt_command.py)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import pytest

from harness.errors import HarnessError
from harness.hunt.margin import FAILED, Assessment
from harness.hunt.search import HuntPlan, hunt
from harness.hunt.shrink import simplifications
from harness.hunt.space import Candidate
from harness.hunt.task import Outcome

Rule = Callable[[Candidate], "tuple[str, float] | None"]  # (kind, margin) or None: passed


def landscape(rule: Rule, log: list[Candidate] | None = None):
    """A run_batch whose outcomes `rule` decides: a failure of its kind, or a margin."""

    def run_batch(candidates: list[Candidate]) -> list[Outcome]:
        outcomes = []
        for candidate in candidates:
            if log is not None:
                log.append(candidate)
            said = rule(candidate)
            if said is None or said[0] == "":
                margin = said[1] if said else 1.0
                assessment = Assessment(False, margin, (), None, "", 5)
            else:
                assessment = Assessment(True, FAILED, (said[0],), 0, f"{said[0]} wrong", 5)
            outcomes.append(Outcome(candidate, assessment, 0.0))
        return outcomes

    return run_batch


def near_threshold(width: float) -> Rule:
    """Fails on the warning when the obstacle stands within `width` of the threshold."""

    def rule(c: Candidate) -> tuple[str, float]:
        if c.obstacle == "none":
            return ("", 1.0)
        gap = abs(c.distance - c.threshold)
        return ("warning", 0.0) if gap < width else ("", min(1.0, gap / c.threshold))

    return rule


def plan(**changes: object) -> HuntPlan:
    return replace(HuntPlan(150, None, 0, 4, 60), **changes)  # type: ignore[arg-type]


def keep(c: Candidate) -> Candidate:
    return c


def test_the_same_seed_makes_the_same_hunt_and_another_seed_another() -> None:
    runs = []
    for seed in (5, 5, 6):
        log: list[Candidate] = []
        hunt(plan(budget=24, seed=seed), landscape(lambda c: ("", 0.5), log), keep)
        runs.append(log)
    assert len(runs[0]) == 24
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_margin_leads_to_a_narrow_band_a_grid_would_miss(seed: int) -> None:
    """A failure only within 1 cm of the threshold: found within 150 runs."""
    result = hunt(plan(seed=seed), landscape(near_threshold(0.01)), keep)
    assert result.found is not None, f"not found in {len(result.runs)} runs"
    assert len(result.runs) <= 150
    assert result.found.assessment is not None and result.found.assessment.kinds == ("warning",)


def test_shrinking_takes_away_everything_the_failure_does_not_need() -> None:
    """Only the 0.0 convention matters: the obstacle, the motion, the fault, the preset go;
    the threshold becomes the lab's 0.5 m."""
    rule: Rule = lambda c: ("phantom obstacle", 0.0) if c.convention == "zero" else None  # noqa: E731
    start = Candidate(
        obstacle="box",
        distance=1.2345,
        bearing=0.7,
        size=0.33,
        motion="turn",
        speed=0.31,
        duration=2.7,
        preset="rplidar_a1",
        convention="zero",
        fault="noise",
        fault_rate=0.17,
        threshold=0.93,
    )
    result = _shrunk_from(start, rule)
    assert result.shrunk is not None
    assert result.shrunk.candidate == Candidate(
        convention="zero",
        duration=0.2,
        threshold=0.5,
        distance=1.2345,
        bearing=0.7,
        size=0.33,
        speed=0.31,
        fault_rate=0.17,
    )
    assert "no obstacle" in result.shrink_steps and "standing still" in result.shrink_steps


def test_shrinking_keeps_what_the_failure_needs_and_rounds_the_rest() -> None:
    """A wall 0.4-0.6 m ahead is needed: it stays, at a round distance and bearing."""

    def rule(c: Candidate) -> tuple[str, float] | None:
        ahead = c.obstacle == "wall" and abs(c.bearing) < 0.3 and 0.4 < c.distance < 0.6
        return ("distance", 0.0) if ahead else None

    start = Candidate(obstacle="wall", distance=0.5377, bearing=0.1234, size=1.777)
    result = _shrunk_from(replace(start, fault="dropouts", motion="straight"), rule)
    assert result.shrunk is not None
    shrunk = result.shrunk.candidate
    assert shrunk.obstacle == "wall" and shrunk.fault == "none" and shrunk.motion == "still"
    assert (shrunk.bearing, shrunk.distance, shrunk.size) == (0.0, 0.5, 2.0)


def test_shrinking_keeps_the_same_way_of_failing() -> None:
    """A simpler candidate failing in another way is not taken."""

    def rule(c: Candidate) -> tuple[str, float] | None:
        if c.convention == "nan":
            return ("angle", 0.0) if c.motion == "turn" else ("distance", 0.0)
        return None

    result = _shrunk_from(Candidate(convention="nan", motion="turn", speed=0.3), rule)
    assert result.shrunk is not None and result.shrunk.candidate.motion == "turn"


def test_every_simplification_is_one_change_and_none_repeats() -> None:
    start = Candidate(obstacle="cylinder", distance=2.345, motion="reverse", fault="spurious")
    steps = simplifications(start)
    assert len({c for _, c in steps}) == len(steps)
    for what, simpler in steps:
        changed = [k for k, v in simpler.as_dict().items() if v != start.as_dict()[k]]
        assert len(changed) == 1, what
    assert steps[0][0] == "no sensor fault"
    assert simplifications(Candidate(duration=0.2)) == []  # the simplest candidate


def test_a_failure_that_does_not_fail_again_is_flaky_and_the_search_goes_on() -> None:
    seen: set[Candidate] = set()

    def once(c: Candidate) -> tuple[str, float] | None:
        first = c not in seen
        seen.add(c)
        return ("answer", 0.0) if first and c.motion == "turn" else None

    result = hunt(plan(budget=40), landscape(once), keep)
    assert result.found is None and result.flaky
    assert len(result.runs) == 40 and result.confirm_runs == len(result.flaky)


def test_the_time_limit_and_runs_that_cannot_be_made() -> None:
    result = hunt(plan(seconds=0.0), landscape(lambda c: None), keep)
    assert result.stopped_by == "time" and not result.runs

    def broken(candidates: list[Candidate]) -> list[Outcome]:
        return [Outcome(c, None, 0.0, "no domain free") for c in candidates]

    with pytest.raises(HarnessError, match="could not be made .no domain free"):
        hunt(plan(), broken, keep)
    with pytest.raises(HarnessError, match="no proposal made a valid scenario"):
        hunt(plan(), landscape(lambda c: None), lambda c: None)


def _shrunk_from(start: Candidate, rule: Rule):
    """A hunt whose first proposal is replaced by `start`, so it is found at once."""
    calls = {"n": 0}

    def first_is_start(c: Candidate) -> Candidate:
        calls["n"] += 1
        return start if calls["n"] == 1 else replace(c, convention="rep117", obstacle="none")

    result = hunt(plan(batch=1), landscape(rule), first_is_start)
    assert result.found is not None and result.found.candidate == start
    return result


def test_a_status_cannot_write_into_the_counterexample_file(tmp_path) -> None:
    """The node's first failure is quoted in a YAML comment as one escaped line: a line
    break of any kind in a status would otherwise end the comment and add keys."""
    from harness.commands.hunt import _write_counterexample
    from harness.scenario.files import load_scenario_file

    said = "status 'a\rthreshold: 9\u2028seed: 7\nobstacles: []' claims an obstacle"
    failing = Outcome(
        Candidate(obstacle="wall", distance=1.0, size=1.0),
        Assessment(True, FAILED, ("phantom obstacle",), 0, said, 3),
        0.0,
    )
    result = hunt(plan(budget=1), landscape(lambda c: None), keep)
    result.shrunk = failing
    _write_counterexample(tmp_path, result, 4, ["fossbot-hil", "run", "x.yaml"])
    scenario = load_scenario_file(tmp_path / "counterexample.yaml")
    assert (scenario.threshold, scenario.seed, len(scenario.obstacles)) == (0.5, 4, 1)
    assert "\\r" in (tmp_path / "counterexample.yaml").read_text()
