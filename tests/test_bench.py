"""`fossbot-hil bench`: every figure is there and numeric; speed is measured, never asserted."""

from __future__ import annotations

import json
import math

import pytest
from command_line import fossbot_hil

from harness.bench.figures import REQUIRED_KEYS, STUDENT_SPLIT_KEYS, SUITE_KEYS
from harness.cli import main


def _number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(180)
def test_quick_json_has_every_figure_and_the_machine() -> None:
    """The suite stage builds node/ with colcon (the `test` extra) and runs each kind once.

    The grade and hil stages, a class graded and a suite in real time, are
    run by their own tests (tests/bench/); here every other stage is."""
    stages = "raycast,synthesis,inprocess,ros2,serial,pacing,suite"
    done = fossbot_hil("bench", "--quick", "--json", "--only", stages, timeout=170)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)  # one JSON object and nothing else on stdout
    # the edit-run loop, split; the workspace node and the inprocess link beside it
    suite = [k for k in SUITE_KEYS if not k.endswith("_runs_s")]
    missing = [k for k in (*REQUIRED_KEYS, *suite) if not _number(report.get(k))]
    assert not missing, f"not numeric: {missing}; errors: {report['errors']}"
    assert all(isinstance(report[k], str) for k in SUITE_KEYS if k.endswith("_runs_s"))
    assert {k: report[k] for k in STUDENT_SPLIT_KEYS} == dict.fromkeys(STUDENT_SPLIT_KEYS)
    machine = report["machine"]
    assert machine["cores"] >= 1 and machine["cpu"] and machine["python"] and machine["os"]
    assert {t["key"] for t in report["targets"]} >= {
        "ros2_lockstep_scans_per_s",
        "overhead_ratio",
        "lab_suite_wall_s",
        "suite_s",
        "student_suite_ratio",
        "inprocess_suite_ratio",
        "serial_rate_error_pct",
        "serial_jitter_p99_ms",
    }
    assert all(isinstance(t["met"], bool) for t in report["targets"] if t["value"] is not None)
    assert report["stages"]["ros2"]["failed_ticks"] == 0


def test_only_the_stages_without_ros(capsys: pytest.CaptureFixture[str]) -> None:
    """Stages left out give null figures; the run still exits 0 (in this process: the
    stages without ROS need no process of their own)."""
    code = main(["bench", "--quick", "--json", "--only", "raycast,inprocess"])
    done = capsys.readouterr()
    assert code == 0, done.err
    report = json.loads(done.out)
    assert _number(report["raycast_scans_per_s"]) and _number(report["inprocess_scans_per_s"])
    assert report["ros2_lockstep_scans_per_s"] is None and report["overhead_ratio"] is None
    assert set(report["stages"]) == {"raycast", "inprocess"}
    assert report["ratio_to_raycast"]["inprocess"] > 0


def test_table_without_json(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["bench", "--quick", "--only", "raycast"])
    done = capsys.readouterr()
    assert code == 0, done.err
    assert "ray casting alone" in done.out and "targets met" in done.out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--only", "nope"], "--only 'nope': unknown stage nope"),
        (["--only", ","], "unknown stage (none given)"),
        (["--repeat", "3"], "unrecognized arguments: --repeat"),
    ],
)
def test_bad_options_are_one_line_and_exit_2(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["bench", *args]) == 2
    done = capsys.readouterr()
    assert done.out == ""
    assert done.err.count("\n") == 1 and message in done.err
