"""Scores, the grading file, the roster and what a student may see (pure: no ROS)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.grading.grade import GradeConfig, ticks_from
from harness.grading.grading_file import load_grading_file
from harness.grading.hidden import HiddenScenario, hidden_run, scrub_text
from harness.grading.roster import parse_roster
from harness.grading.scoring import ScenarioScore, ScorePlan
from harness.judge.records import RunResult
from harness.judge.verdicts import verdict_of
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

PLAN = ScorePlan(
    (
        ScenarioScore("approach_wall", 1.0),
        ScenarioScore("out_of_range", 2.0),
        ScenarioScore("narrow_corridor", 3.0, hidden=True, label="hidden 1"),
    ),
    points=100.0,
)


def test_weights_scale_to_the_points_and_only_a_pass_earns() -> None:
    assert PLAN.max_score == 100.0
    assert PLAN.max_points("out_of_range") == pytest.approx(100 * 2 / 6)
    verdicts = {"approach_wall": "PASS", "out_of_range": "FAIL", "narrow_corridor": "PASS"}
    assert PLAN.score(verdicts) == pytest.approx(round(100 * 4 / 6, 2))
    assert PLAN.score({}) == 0.0


def test_without_a_grading_file_the_score_counts_the_scenarios_passed() -> None:
    plan = ScorePlan.equal(["a", "b", "c"])
    assert plan.score({"a": "PASS", "b": "ERROR", "c": "PASS"}) == 2.0
    assert plan.max_score == 3.0


def test_partial_credit_counts_the_ticks_held_of_those_planned() -> None:
    plan = ScorePlan((ScenarioScore("a", 1.0), ScenarioScore("b", 1.0)), partial_credit=True)
    # b broke after 10 of its 40 planned ticks, 9 of them held: 9/40 of its point
    assert plan.score({"a": "PASS", "b": "ERROR"}, {"b": (9, 40)}) == pytest.approx(1.23)


def test_a_scenario_that_broke_early_counts_its_missing_ticks_as_not_held() -> None:
    config = GradeConfig(
        scenarios=("a", "b", "c"),
        scenario_refs=("a", "b", "c"),
        link="ros2",
        options=LinkOptions(),
        settings=RunSettings(),
        students_dir=Path("/nowhere/students"),
        build_timeout=1.0,
        student_timeout=1.0,
        planned={"a": 95, "b": 64, "c": 50},
    )
    data = {
        "results": [
            {"scenario": "a", "ticks": 95, "failed_ticks": 0},
            {"scenario": "b", "ticks": 3, "failed_ticks": 1},  # crashed at tick 3
        ]
    }
    assert ticks_from(data, config) == {"a": (95, 95), "b": (2, 64), "c": (0, 50)}


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_the_grading_file_names_files_relative_to_itself(tmp_path: Path) -> None:
    grading = write(
        tmp_path / "course" / "grading.yaml",
        "scenarios:\n  - approach_wall\n  - scenario: hidden/corridor.yaml\n"
        "    weight: 3\n    hidden: true\npoints: 10\nthreshold: 0.4\nfaults: [dropouts]\n",
    )
    loaded = load_grading_file(grading)
    first, second = loaded.planned
    assert first.scenario == "approach_wall"
    assert second.scenario == str((tmp_path / "course" / "hidden" / "corridor.yaml").resolve())
    assert (second.hidden, second.label, second.weight) == (True, "hidden 1", 3.0)
    assert loaded.request_values() == {"threshold": 0.4, "faults": ["dropouts"]}


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("scenarios:\n  - scenario: a\n    wieght: 2\n", "scenarios.0.wieght: Extra inputs"),
        ("scenarios: []\n", "scenarios: List should have at least 1 item"),
        ("scenarios:\n  - scenario: a\n    weight: 0\n", "every scenario has weight 0"),
        ("scenarios:\n  - scenario: a\n    weight: -1\n", "scenarios.0.weight"),
        ("- a\n", "expected a mapping with a 'scenarios' list"),
        ("scenarios: [a]\nthreshold: fast\n", "threshold"),
        ("scenarios: [a\n", "YAML"),
        ("scenarios: [a]\ngradebook: {column: Student}\n", "Canvas reads that header"),
        ("scenarios: [a]\ngradebook: {ids: Email}\n", "gradebook.ids"),
    ],
)
def test_a_bad_grading_file_is_one_line_naming_the_field(
    tmp_path: Path, text: str, says: str
) -> None:
    path = write(tmp_path / "grading.yaml", text)
    with pytest.raises(ConfigError) as caught:
        load_grading_file(path)
    message = str(caught.value)
    assert message.startswith(f"--grading {path}: ")
    assert says in message
    assert "\n" not in message


def test_the_grading_file_names_the_gradebook_columns(tmp_path: Path) -> None:
    default = load_grading_file(write(tmp_path / "a.yaml", "scenarios: [a]\n")).gradebook
    assert (default.column, default.ids) == ("Lab 07", "SIS User ID")
    text = "scenarios: [a]\ngradebook: {column: Lab 7b, ids: SIS Login ID}\n"
    given = load_grading_file(write(tmp_path / "b.yaml", text)).gradebook
    assert (given.column, given.ids) == ("Lab 7b", "SIS Login ID")


def test_a_missing_grading_file_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no such grading file"):
        load_grading_file(tmp_path / "grading.yaml")


def test_the_roster_maps_folders_to_ids() -> None:
    roster = parse_roster("\ufeffFolder, ID ,Name\nalex,s1,Alex K\nbea,s2,\n")
    assert roster.entry_for("alex").id == "s1"  # type: ignore[union-attr]
    assert roster.entry_for("mon/ALEX").name == "Alex K"  # type: ignore[union-attr]
    assert roster.entry_for("carl") is None


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("", "empty"),
        ("name,email\nalex,a@x\n", "must name the columns folder and id"),
        ("folder,id\nalex,s1\nbea,s1\n", "line 3: id 's1' is also on line 2"),
        ("folder,id\nalex,s1\nAlex,s2\n", "line 3: folder 'Alex' is also on line 2"),
        ("folder,id\nalex,\n", "line 2: every row needs a folder and an id"),
    ],
)
def test_an_ambiguous_roster_is_a_usage_error(text: str, says: str) -> None:
    with pytest.raises(ConfigError, match=says):
        parse_roster(text, "--roster r.csv")


def test_a_hidden_scenario_shows_only_its_label_and_verdict() -> None:
    failed = RunResult("narrow_corridor", "ros2", 7, 0.5, "none", error="node died at tick 4")
    shown = hidden_run(failed, HiddenScenario("hidden 1"))
    assert (shown.scenario, verdict_of(shown), shown.first_failure) == (
        "hidden 1",
        "ERROR",
        "hidden 1: failed",
    )
    allowed = hidden_run(failed, HiddenScenario("hidden 1", show_failure=True))
    assert allowed.first_failure == "hidden 1: node died at tick 4"
    passed = hidden_run(RunResult("narrow_corridor", "ros2", 7, 0.5, "none"), HiddenScenario("h"))
    assert verdict_of(passed) == "PASS"
    assert passed.records == [] and passed.seed == 0


def test_paths_are_replaced_longest_first() -> None:
    pairs = [("/home/t/class/", ""), ("/home/t/class/alex/", ""), ("/usr/bin/python3", "python3")]
    text = "/usr/bin/python3 /home/t/class/alex/node.py; see /home/t/class/grades.csv"
    assert scrub_text(text, pairs) == "python3 node.py; see grades.csv"


def test_grading_into_an_earlier_output_says_what_it_replaces(tmp_path: Path) -> None:
    from harness.commands.grade import previous_grading
    from harness.grading.discover import GRADES_MARKER

    out = tmp_path / "grades"
    assert previous_grading(out) is None  # nothing there
    out.mkdir()
    (out / "grades.csv").write_text("student,passed\r\nalex,1/1\r\nbea,0/1\r\n")
    assert previous_grading(out) is None  # not ours: check_out refuses it instead
    (out / GRADES_MARKER).write_text("written by fossbot-hil grade\n")
    said = previous_grading(out)
    assert said is not None
    assert said.startswith("replacing the grading of 2 students from ")
    assert said.endswith(f" in {out}")


def test_a_fifo_given_as_the_roster_is_refused_without_waiting(tmp_path: Path) -> None:
    import os

    from harness.grading.roster import load_roster

    fifo = tmp_path / "roster.csv"
    os.mkfifo(fifo)  # nobody writes to it: opening it to read would wait for ever
    with pytest.raises(ConfigError, match="not a regular file"):
        load_roster(fifo)
