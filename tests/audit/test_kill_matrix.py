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


def test_a_unit_that_did_not_finish_is_named() -> None:
    gone = Unit("slow_callback", error="stopped after 300 s")
    matrix = kill_matrix(SCENARIOS, [gone], control())
    assert matrix.unit_errors == {"slow_callback": "stopped after 300 s"}
    assert matrix.survivors == ("slow_callback",)
