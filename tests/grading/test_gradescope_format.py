"""gradescope_results: Gradescope's documented results.json, hidden scenarios by label (pure)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from gradescope_schema import check_gradescope

from harness.grading.class_table import ERROR, FAIL, NOT_RUN, PASS
from harness.grading.gradescope import gradescope_results, not_graded_results
from harness.grading.scoring import ScenarioScore, ScorePlan

PLAN = ScorePlan(
    (
        ScenarioScore("approach_wall", 1.0),
        ScenarioScore("out_of_range", 2.0),
        ScenarioScore("secret_maze", 3.0, hidden=True, label="hidden 1"),
        ScenarioScore("doorway", 2.0, hidden=True, show_failure=True, label="hidden 2"),
    ),
    points=10.0,
    partial_credit=True,
)
VERDICTS = {"approach_wall": PASS, "out_of_range": FAIL, "secret_maze": FAIL, "doorway": ERROR}
TICKS = {"approach_wall": (95, 95), "out_of_range": (48, 64), "secret_maze": (10, 40)}
FAILURES = {
    "out_of_range": "out_of_range: t=0.00 s tick 0: expected no obstacle; "
    "raised at /home/ta/course/student/node.py:12",
    "secret_maze": "secret_maze: t=1.20 s tick 12: expected a warning within 0.5 m of the wall",
    "doorway": "doorway: node exited with code 1; last stderr: File "
    '"/autograder/submission/node.py", line 3 (after secret_maze)',
}


def results(**kwargs: object) -> dict:
    data = gradescope_results(PLAN, VERDICTS, TICKS, FAILURES, **kwargs)  # type: ignore[arg-type]
    check_gradescope(json.loads(json.dumps(data)))  # what is written is what is checked
    return data


def test_one_test_per_scenario_in_plan_order_with_points() -> None:
    data = results(execution_time=12.6)
    tests = data["tests"]
    assert [t["name"] for t in tests] == ["approach_wall", "out_of_range", "hidden 1", "hidden 2"]
    assert [t["max_score"] for t in tests] == [1.25, 2.5, 3.75, 2.5]  # weights scaled to 10
    assert [t["status"] for t in tests] == ["passed", "failed", "failed", "failed"]
    # partial credit: a failed scenario earns its share of the ticks held
    assert [t["score"] for t in tests] == [1.25, 1.88, 0.94, 0.0]
    assert data["score"] == PLAN.score(VERDICTS, TICKS) == 4.06
    assert data["execution_time"] == 13
    assert all(t["visibility"] == "visible" for t in tests)


def test_visible_outputs_say_the_failure_and_the_ticks_without_grader_paths() -> None:
    tests = results()["tests"]
    assert tests[0]["output"] == "passed\nticks held: 95 of 95"
    assert tests[1]["output"] == (
        "out_of_range: t=0.00 s tick 0: expected no obstacle; raised at node.py:12\n"
        "ticks held: 48 of 64"
    )


def test_a_hidden_scenario_shows_its_label_and_whether_it_passed_only() -> None:
    data = results(hidden_names={"/home/ta/course/hidden/maze.yaml": "hidden 1"})
    text = json.dumps(data)
    assert "secret_maze" not in text and "maze" not in text and "/home" not in text
    hidden_1, hidden_2 = data["tests"][2], data["tests"][3]
    assert hidden_1["output"] == "failed"  # no ticks, no failure: show_failure is false
    # show_failure: its first failure, itself and every other hidden one by label
    assert hidden_2["output"] == (
        'hidden 2: node exited with code 1; last stderr: File "node.py", line 3 (after hidden 1)'
    )


def test_notes_and_output_go_to_the_top_as_plain_text() -> None:
    data = results(
        notes=["launch/lab.launch.py sets lidar_info_topic, which the node does not declare"],
        output="3 of 4 scenarios passed\n\x1b[31mred\x1b[0m /home/ta/x/run.log",
    )
    assert data["output"] == (
        "note: launch/lab.launch.py sets lidar_info_topic, which the node does not declare\n"
        "3 of 4 scenarios passed\n\\x1b[31mred\\x1b[0m run.log"
    )
    assert data["output_format"] == data["test_output_format"] == "text"
    assert data["test_name_format"] == "text"
    assert data["stdout_visibility"] == "hidden"  # the run's whole stdout is the grader's


def test_verdicts_missing_are_not_run_and_a_pass_needs_no_ticks() -> None:
    plan = ScorePlan.equal(["a", "b"])
    data = gradescope_results(plan, {"a": PASS}, {}, {})
    check_gradescope(data)
    assert [(t["score"], t["max_score"], t["status"], t["output"]) for t in data["tests"]] == [
        (1.0, 1.0, "passed", "passed"),
        (0.0, 1.0, "failed", "not run"),
    ]
    assert data["score"] == 1.0 and "execution_time" not in data


@pytest.mark.parametrize("verdict", [FAIL, ERROR, NOT_RUN])
def test_without_partial_credit_a_failed_scenario_earns_nothing(verdict: str) -> None:
    plan = ScorePlan((ScenarioScore("a", 2.0),))
    data = gradescope_results(plan, {"a": verdict}, {"a": (90, 95)}, {"a": "a: failed"})
    assert data["score"] == 0.0 and data["tests"][0]["score"] == 0.0


def test_not_graded_results_give_every_scenario_nothing_and_say_why() -> None:
    reason = "did not build: setup.py line 18: SyntaxError (in /autograder/submission)"
    data = not_graded_results(PLAN, reason, execution_time=3)
    check_gradescope(data)
    assert data["score"] == 0.0
    assert [t["status"] for t in data["tests"]] == ["failed"] * 4
    assert (
        data["output"] == "not graded: did not build: setup.py line 18: SyntaxError (in submission)"
    )
    assert data["tests"][0]["output"] == data["output"]
    assert data["tests"][2]["name"] == "hidden 1" and data["tests"][2]["output"] == "failed"


def test_the_schema_check_refuses_what_gradescope_does_not_document() -> None:
    good = results()
    for broken in (
        {**good, "tests": [{**good["tests"][0], "visibility": "students"}]},
        {**good, "tests": [{**good["tests"][0], "status": "error"}]},
        {**good, "tests": [{**good["tests"][0], "max_points": 1}]},
        {**good, "score": "4"},
        {"tests": [{"name": "x"}]},
    ):
        with pytest.raises(AssertionError):
            check_gradescope(broken)


def test_the_lms_modules_are_pure() -> None:
    """gradescope, gradebook and student_text import neither rclpy nor pybullet."""
    code = (
        "import sys\n"
        "import harness.grading.gradebook, harness.grading.gradescope\n"
        "import harness.grading.student_text\n"
        "print(' '.join(m for m in ('rclpy', 'pybullet') if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""
