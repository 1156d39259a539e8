"""`fossbot-hil run --gradescope FILE` (and `--grading`), run for real: results.json for one
submission, hidden scenarios by label on every output, usage errors before anything runs."""

from __future__ import annotations

import shlex
import shutil
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from command_line import fossbot_hil
from gradescope_schema import read_results
from grading_class import script_student

from harness.cli import main

REPO = Path(__file__).resolve().parents[2]
SHIPPED = REPO / "harness" / "scenarios"
BUGGY = f"{REPO / 'tests' / 'student_functions.py'}:crash_when_nothing_in_range"


def course(tmp_path: Path, grading: str) -> Path:
    """A grading file with two hidden scenarios, copies of shipped ones under secret names."""
    folder = tmp_path / "course"
    (folder / "hidden").mkdir(parents=True)
    shutil.copy(SHIPPED / "out_of_range.yaml", folder / "hidden" / "secret_range.yaml")
    shutil.copy(SHIPPED / "drive_past_10m.yaml", folder / "hidden" / "far_away.yaml")
    (folder / "grading.yaml").write_text(grading)
    return folder / "grading.yaml"


HIDDEN_GRADING = """\
scenarios:
  - scenario: approach_wall
    weight: 2
  - scenario: hidden/secret_range.yaml
    weight: 3
    hidden: true
  - scenario: hidden/far_away.yaml
    weight: 5
    hidden: true
    show_failure: true
points: 20
partial_credit: true
"""


def test_run_writes_gradescope_results_showing_hidden_scenarios_by_label(tmp_path: Path) -> None:
    grading = course(tmp_path, HIDDEN_GRADING)
    out, junit = tmp_path / "results.json", tmp_path / "junit.xml"
    done = fossbot_hil(
        "run",
        "--link",
        "inprocess",
        "--processor",
        BUGGY,
        "--grading",
        str(grading),
        "--gradescope",
        str(out),
        "--junit-xml",
        str(junit),
    )
    assert done.returncode == 1, done.stderr  # an expectation failed, as without --gradescope
    data = read_results(out)
    tests = {t["name"]: t for t in data["tests"]}
    assert list(tests) == ["approach_wall", "hidden 1", "hidden 2"]
    assert [t["max_score"] for t in tests.values()] == [4.0, 6.0, 10.0]
    assert tests["approach_wall"]["status"] == "passed" and tests["approach_wall"]["score"] == 4
    # the processing function raises once nothing is in range: on the first tick of the
    # one, part way through the other (partial credit: its share of the ticks held)
    assert tests["hidden 1"] == {
        "name": "hidden 1",
        "score": 0.0,
        "max_score": 6.0,
        "status": "failed",
        "output": "failed",
        "visibility": "visible",
    }
    far = tests["hidden 2"]
    assert far["status"] == "failed" and 0 < far["score"] < 10
    assert (
        far["output"].startswith("hidden 2: t=") and "processing function raised" in far["output"]
    )
    assert data["score"] == pytest.approx(4 + far["score"], abs=0.011)
    # no output a student sees names a hidden scenario or its file, nor a grader's path
    for text in (out.read_text(), done.stdout, junit.read_text()):
        assert "secret_range" not in text and "far_away" not in text
    assert str(tmp_path) not in out.read_text()
    assert "hidden 1" in done.stdout and "hidden 2" in done.stdout
    assert f"score: {data['score']:g} of 20" in done.stdout
    cases = [c.get("name") for c in ET.parse(junit).getroot().iter("testcase")]
    assert cases == ["approach_wall", "hidden 1", "hidden 2"]


def test_without_a_grading_file_every_scenario_weighs_one(tmp_path: Path) -> None:
    out = tmp_path / "results.json"
    done = fossbot_hil(
        "run", "approach_wall", "out_of_range", "--link", "inprocess", "--gradescope", str(out)
    )
    assert done.returncode == 0, done.stderr
    data = read_results(out)
    assert data["score"] == 2.0
    assert [(t["name"], t["score"], t["max_score"]) for t in data["tests"]] == [
        ("approach_wall", 1.0, 1.0),
        ("out_of_range", 1.0, 1.0),
    ]
    assert data["tests"][0]["output"] == "passed\nticks held: 95 of 95"


def test_options_typed_win_over_the_grading_file_even_at_their_default(tmp_path: Path) -> None:
    """The file's timeout (0.01 s) fails a processing function that takes 50 ms; a typed
    --timeout 1, argparse's default value, still wins over it."""
    slow = tmp_path / "slow.py"
    slow.write_text(
        "import time\nfrom harness.links.inprocess import reference_processor\n\n\n"
        "def process(scan, threshold):\n    time.sleep(0.05)\n"
        "    return reference_processor(scan, threshold)\n"
    )
    grading = tmp_path / "grading.yaml"
    grading.write_text("scenarios: [out_of_range]\ntimeout: 0.01\n")
    common = ["run", "--link", "inprocess", "--processor", f"{slow}:process"]
    common += ["--grading", str(grading)]
    file_timeout = fossbot_hil(*common)
    assert file_timeout.returncode == 1 and "did not return within 0.01 s" in file_timeout.stdout
    typed = fossbot_hil(*common, "--timeout", "1")
    assert typed.returncode == 0, typed.stdout + typed.stderr
    assert "score: 1 of 1" in typed.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["approach_wall", "--grading", "{grading}"], "the grading file lists the scenarios"),
        (["--grading", "{missing}"], "missing.yaml: no such grading file"),
        (["--gradescope", "{folder}"], "--gradescope {folder}: a folder, not a file"),
        (["--gradescope", "{nowhere}"], "its folder does not exist"),
        (["--gradescope", "{out}", "--watch"], "--gradescope cannot go with --watch"),
        (["--grading", "{hidden}", "--out", "{folder}/report"], "--out cannot go with --grading"),
        (["--grading", "{hidden}", "--gui"], "it has hidden scenarios, and the viewer"),
        (["approach_wall", "approach_wall", "--gradescope", "{out}"], "given twice"),
        (["--gradescope", ""], "must not be empty"),
    ],
)
def test_usage_errors_exit_2_with_one_line_and_write_nothing(
    args: list[str], needle: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "grading.yaml").write_text("scenarios: [approach_wall]\n")
    hidden = course(tmp_path, HIDDEN_GRADING)
    (tmp_path / "folder").mkdir()
    places = {
        "{grading}": str(tmp_path / "grading.yaml"),
        "{hidden}": str(hidden),
        "{missing}": str(tmp_path / "missing.yaml"),
        "{folder}": str(tmp_path / "folder"),
        "{nowhere}": str(tmp_path / "nowhere" / "results.json"),
        "{out}": str(tmp_path / "results.json"),
    }
    argv = list(args)
    for key, value in places.items():
        argv = [a.replace(key, value) for a in argv]
        needle = needle.replace(key, value)
    assert main(["run", "--link", "inprocess", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("fossbot-hil: error: "), err
    assert needle in err
    assert not (tmp_path / "results.json").exists()
    assert not (tmp_path / "folder" / "report").exists()


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(240)
def test_a_script_node_over_ros2_gets_its_results_json(tmp_path: Path) -> None:
    """A student's node script over ROS 2: full marks; the grading file's ready timeout
    (far too short for any node) loses to the one typed, which is argparse's default."""
    student = script_student(tmp_path / "student")
    grading = course(
        tmp_path,
        "scenarios:\n  - approach_wall\n  - scenario: hidden/secret_range.yaml\n"
        "    hidden: true\npoints: 10\nready_timeout: 0.01\ntimeout: 2\n",
    )
    out = tmp_path / "results.json"
    node = f"{shlex.quote(sys.executable)} {shlex.quote(str(student / 'lidar_node.py'))}"
    done = fossbot_hil(
        "run",
        "--node",
        node,
        "--grading",
        str(grading),
        "--ready-timeout",
        "20",
        "--gradescope",
        str(out),
        timeout=200,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    data = read_results(out)
    assert data["score"] == 10.0
    assert [(t["name"], t["score"], t["status"]) for t in data["tests"]] == [
        ("approach_wall", 5.0, "passed"),
        ("hidden 1", 5.0, "passed"),
    ]
    assert "secret_range" not in done.stdout and "secret_range" not in out.read_text()
