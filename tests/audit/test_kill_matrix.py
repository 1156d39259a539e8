"""The kill matrix from units' verdicts (pure): kills, survivors, flips, and scenarios the
correct node fails, which kill nothing."""

from __future__ import annotations

from dataclasses import dataclass, field

from harness.audit.matrix import kill_matrix

SCENARIOS = ("approach_wall", "out_of_range")


@dataclass
class Unit:
    """A unit's verdicts per scenario, one per seed."""

    name: str
    seen: dict[str, list[str]] = field(default_factory=dict)
    error: str | None = None

    def verdicts(self, scenario: str) -> list[str]:
        return self.seen.get(scenario, [])

    def first_failure(self, scenario: str) -> str:
        return f"{scenario}: tick 3: wrong" if "FAIL" in self.seen.get(scenario, []) else ""


PASSED = {"out_of_range": ["PASS", "PASS"]}


def control(**seen: list[str]) -> Unit:
    return Unit(
        "correct", {"approach_wall": ["PASS", "PASS"], "out_of_range": ["PASS", "PASS"]} | seen
    )


def test_a_mutant_failed_in_every_seed_is_killed_and_explained() -> None:
    degrees = Unit(
        "angle_in_degrees", {"approach_wall": ["FAIL", "FAIL"], "out_of_range": ["PASS", "PASS"]}
    )
    matrix = kill_matrix(SCENARIOS, [degrees], control())
    assert matrix.killed_by["angle_in_degrees"] == ("approach_wall",)
    assert matrix.cells["angle_in_degrees", "out_of_range"] == "survived"
    assert matrix.why["angle_in_degrees"] == "approach_wall: tick 3: wrong"
    assert matrix.survivors == () and matrix.score == (1, 1)


def test_an_error_kills_as_a_fail_does() -> None:
    crash = Unit("crash_when_nothing_in_range", {"out_of_range": ["ERROR", "ERROR"]})
    matrix = kill_matrix(SCENARIOS, [crash], control())
    assert matrix.killed_by["crash_when_nothing_in_range"] == ("out_of_range",)


def test_a_verdict_that_changes_with_the_seed_is_a_flip_not_a_kill() -> None:
    late = Unit(
        "one_scan_late", {"approach_wall": ["FAIL", "PASS"], "out_of_range": ["PASS", "PASS"]}
    )
    matrix = kill_matrix(SCENARIOS, [late], control())
    assert matrix.survivors == ("one_scan_late",)
    assert [f.as_dict() for f in matrix.flips] == [
        {"mutant": "one_scan_late", "scenario": "approach_wall", "verdicts": ["FAIL", "PASS"]}
    ]


def test_a_scenario_the_correct_node_fails_kills_nothing() -> None:
    degrees = Unit(
        "angle_in_degrees", {"approach_wall": ["FAIL", "FAIL"], "out_of_range": ["FAIL", "FAIL"]}
    )
    matrix = kill_matrix(SCENARIOS, [degrees], control(out_of_range=["PASS", "FAIL"]))
    assert matrix.killed_by["angle_in_degrees"] == ("approach_wall",)
    assert set(matrix.unsound) == {"out_of_range"}
    assert matrix.unsound["out_of_range"].startswith("PASS/FAIL: out_of_range: tick 3")


def test_a_unit_that_did_not_finish_is_an_error_neither_a_survivor_nor_a_kill() -> None:
    """Its reason is kept, and the score counts only the mutants that were judged."""
    gone = Unit("slow_callback", {"approach_wall": ["FAIL", "FAIL"]}, error="stopped after 300 s")
    degrees = Unit("angle_in_degrees", {"approach_wall": ["FAIL", "FAIL"]})
    latched = Unit("warning_latched", {"approach_wall": ["PASS", "PASS"]} | PASSED)
    matrix = kill_matrix(SCENARIOS, [gone, degrees, latched], control())
    assert matrix.unit_errors == {"slow_callback": "stopped after 300 s"}
    assert matrix.status("slow_callback") == "error" and matrix.errors == ("slow_callback",)
    assert matrix.killed_by["slow_callback"] == ()
    assert matrix.survivors == ("warning_latched",)
    assert matrix.score == (1, 2)  # angle_in_degrees of the two that ran


def test_a_scenario_a_mutant_did_not_run_is_no_pass() -> None:
    """Its node did not start in approach_wall, so out_of_range was not run: nothing says
    the suite lets it pass."""
    lost = Unit("centimetres", {"approach_wall": ["NOT RUN"], "out_of_range": ["NOT RUN"]})
    half = Unit("warning_never", {"approach_wall": ["PASS"], "out_of_range": ["NOT RUN"]})
    matrix = kill_matrix(SCENARIOS, [lost, half], control())
    assert matrix.cells["warning_never", "out_of_range"] == "not run"
    assert matrix.errors == ("centimetres", "warning_never") and matrix.survivors == ()
    assert matrix.unit_errors["warning_never"].startswith("out_of_range: ")
    assert matrix.score == (0, 0)


def test_a_kill_where_the_correct_node_could_not_run_is_unknown() -> None:
    """The control errored in approach_wall: a mutant failing it is neither killed (the
    scenario may be at fault) nor a survivor (it did fail); one that passed every scenario
    is a survivor all the same."""
    degrees = Unit("angle_in_degrees", {"approach_wall": ["FAIL", "FAIL"]} | PASSED)
    latched = Unit("warning_latched", {"approach_wall": ["PASS", "PASS"]} | PASSED)
    matrix = kill_matrix(SCENARIOS, [degrees, latched], control(approach_wall=["ERROR", "PASS"]))
    assert matrix.unjudged == {"approach_wall"}
    assert matrix.status("angle_in_degrees") == "error"
    assert "the correct node could not run it" in matrix.unit_errors["angle_in_degrees"]
    assert matrix.survivors == ("warning_latched",)


def test_a_control_that_did_not_finish_is_named_and_judges_nothing() -> None:
    """Every unit errored (the whole audit could not run): no kill, no survivor, 0 judged."""
    units = [Unit(name, error="lost to the cluster") for name in ("centimetres", "goes_silent")]
    matrix = kill_matrix(SCENARIOS, units, Unit("correct", error="lost to the cluster"))
    assert matrix.survivors == () and matrix.errors == ("centimetres", "goes_silent")
    assert matrix.unit_errors["correct"] == "lost to the cluster"
    assert matrix.score == (0, 0) and matrix.unjudged == set(SCENARIOS)
