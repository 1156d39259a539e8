"""From a worker's results (or their absence) to a student's verdicts and first failure."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from harness.grading.grade import GradeConfig, verdicts_and_failures
from harness.grading.process import Finished
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

SCENARIOS = ("approach_wall", "drive_past_10m", "out_of_range")
FOLDER = Path("/grades/students/ana")
CONFIG = GradeConfig(
    scenarios=SCENARIOS,
    scenario_refs=SCENARIOS,
    link="ros2",
    options=LinkOptions(),
    settings=RunSettings(),
    students_dir=FOLDER.parent,
    build_timeout=300,
    student_timeout=5,
)
EXITED = Finished(returncode=0, wall_s=1.0)


def entry(scenario: str, verdict: str, **more: Any) -> dict[str, Any]:
    return {"scenario": scenario, "verdict": verdict, **more}


def verdicts_from(*args: Any) -> tuple[dict[str, str], str]:
    """Each scenario's verdict and the first failure a student reads, in the suite's order."""
    verdicts, failures = verdicts_and_failures(*args)
    return verdicts, next((failures[n] for n in SCENARIOS if n in failures), "")


@pytest.mark.parametrize(
    ("data", "finished", "verdicts", "first"),
    [
        (
            {
                "finished": True,
                "results": [
                    entry("approach_wall", "PASS"),
                    entry("drive_past_10m", "FAIL", first_failure="drive_past_10m: t=1.0 s: x"),
                    entry("out_of_range", "FAIL", first_failure="out_of_range: y"),
                ],
            },
            EXITED,
            ["PASS", "FAIL", "FAIL"],
            "drive_past_10m: t=1.0 s: x",
        ),
        (
            {
                "finished": True,
                "results": [
                    entry(
                        "approach_wall",
                        "ERROR",
                        not_started=True,
                        error=f"node from workspace {FOLDER}/colcon/install exited with code 1",
                    ),
                    entry("drive_past_10m", "NOT RUN", not_run=True),
                    entry("out_of_range", "NOT RUN", not_run=True),
                ],
            },
            EXITED,
            ["ERROR", "NOT RUN", "NOT RUN"],
            "node did not start: node from workspace colcon/install exited with code 1",
        ),
        (
            {"finished": False, "error": "--package p: not found", "results": []},
            EXITED,
            ["NOT RUN"] * 3,
            "node did not start: --package p: not found",
        ),
        (
            {"finished": False, "error": "stopped", "results": [entry("approach_wall", "PASS")]},
            Finished(returncode=1, wall_s=5.0, timed_out=True),
            ["PASS", "ERROR", "NOT RUN"],
            "drive_past_10m: stopped: the suite took longer than 5 s",
        ),
        (
            {},
            Finished(returncode=1, wall_s=0.5),
            ["ERROR", "NOT RUN", "NOT RUN"],
            "approach_wall: the test run crashed (exit code 1; see run.log)",
        ),
        (
            {"finished": False, "error": "stopped", "results": []},
            Finished(returncode=1, wall_s=0.5, cancelled=True),
            ["NOT RUN"] * 3,
            "approach_wall: interrupted",
        ),
    ],
    ids=["judged", "never-started", "unresolvable", "timed-out", "crashed", "interrupted"],
)
def test_verdicts_and_first_failure(
    data: dict[str, Any], finished: Finished, verdicts: list[str], first: str
) -> None:
    """Every scenario gets a verdict; the first failure is the one a student reads first."""
    got, why = verdicts_from(data, finished, CONFIG, FOLDER)
    assert list(got) == list(SCENARIOS)
    assert list(got.values()) == verdicts
    assert why == first


def test_a_script_is_named_by_its_file_not_the_command() -> None:
    """'node /venv/bin/python /class/ana/node.py exited' reads 'node node.py exited'."""
    command = "/venv/bin/python /class/ana/node.py"
    data = {
        "finished": True,
        "results": [
            entry("approach_wall", "ERROR", not_started=True, error=f"node {command} exited")
        ],
    }
    _, why = verdicts_from(data, EXITED, CONFIG, FOLDER, command)
    assert why == "node did not start: node node.py exited"
