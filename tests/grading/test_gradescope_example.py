"""examples/gradescope/, run for real: setup.sh installs fossbot-hil into an autograder root,
run_autograder grades submissions there and always leaves a results.json in Gradescope's
documented format.

The root is a temporary folder laid out as Gradescope lays out /autograder
(AUTOGRADER_ROOT): source/ holds the example's files and a copy of this working
tree as fossbot-hil/ (what the instructor zips), submission/ a student's hand-in.
What is not played: apt-get and making the virtual environment. setup.sh finds
one already made (it reuses an existing one), made without pip and borrowing this
project's installed packages through a .pth file, so its lock step installs only
the few pins this environment lacks instead of 400 MB of wheels; fossbot-hil
itself is built and installed for real from the copy, and the setup's own check
runs a scenario over ROS 2. The ROS 2 wheels' libraries are found through the
LD_LIBRARY_PATH this interpreter's bootstrapper set, as in tests/ci_templates.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

import pytest
from borrowed_venv import borrowing_venv
from gradescope_schema import read_results
from grading_class import broken_setup_package, script_student

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(900)]

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "gradescope"
STEP_TIMEOUT_S = 600


def working_tree_copy(target: Path) -> Path:
    """The working tree's files (tracked and new, not ignored): the release in the zip."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=REPO,
        capture_output=True,
        check=True,
        timeout=60,
    ).stdout.decode()
    for name in filter(None, listed.split("\0")):
        source = REPO / name
        if source.is_symlink():  # harness/scenarios -> ../scenarios, ...: kept as links
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            (target / name).symlink_to(os.readlink(source))
            continue
        if not source.is_file():
            continue
        (target / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target / name)
    return target


def environment(root: Path, **more: str) -> dict[str, str]:
    """What a Gradescope container gives the scripts: no pip configuration or ROS of this
    machine, the autograder root where the test put it."""
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.startswith(("PIP_", "PYTHON", "VIRTUAL_ENV", "ROS_", "COLCON", "AMENT"))
    }
    project_bin = str(Path(sys.executable).parent)  # colcon, as the borrowed packages' script
    env.update(
        PATH=os.pathsep.join([env.get("PATH", ""), project_bin]),
        PIP_CONFIG_FILE=os.devnull,
        PIP_DISABLE_PIP_VERSION_CHECK="1",
        AUTOGRADER_ROOT=str(root),
        FOSSBOT_HIL_CACHE_DIR=str(root / "cache"),
    )
    env.update(more)
    return env


def script(path: Path, env: Mapping[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(path)],
        cwd=env["AUTOGRADER_ROOT"],
        env=dict(env),
        capture_output=True,
        text=True,
        timeout=STEP_TIMEOUT_S,
        check=False,
    )


@pytest.fixture(scope="module")
def autograder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An autograder root after setup.sh ran in it."""
    root = tmp_path_factory.mktemp("autograder")
    source = root / "source"
    shutil.copytree(EXAMPLE, source)  # the zip: setup.sh, run_autograder, grading.yaml, ...
    working_tree_copy(source / "fossbot-hil")
    borrowing_venv(root / "fossbot-hil-venv")
    done = script(source / "setup.sh", environment(root))
    assert done.returncode == 0, f"setup.sh failed:\n{done.stdout[-4000:]}\n{done.stderr[-4000:]}"
    assert "1 of 1 scenario passed" in done.stdout  # its check: a scenario over ROS 2
    installed = root / "fossbot-hil-venv" / "lib"
    assert list(installed.glob("python*/site-packages/harness/cli.py")), "not installed"
    return root


def grade(root: Path, hand_in: object, **env: str) -> tuple[dict, str]:
    """run_autograder on a fresh submission/ made by `hand_in(folder)`; its results."""
    submission = root / "submission"
    shutil.rmtree(submission, ignore_errors=True)
    if hand_in is not None:
        hand_in(submission)  # type: ignore[operator]
    else:
        submission.mkdir()
    done = script(root / "source" / "run_autograder", environment(root, **env))
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    results = root / "results" / "results.json"
    data = read_results(results)
    text = results.read_text()
    assert str(root) not in text and "doorway" not in text  # no grader path, no hidden name
    return data, done.stdout


def test_a_correct_script_node_earns_every_point(autograder: Path) -> None:
    data, stdout = grade(autograder, script_student)
    assert data["score"] == 10.0, data
    assert [(t["name"], t["max_score"], t["status"]) for t in data["tests"]] == [
        ("approach_wall", 2.0, "passed"),
        ("drive_past_10m", 1.0, "passed"),
        ("out_of_range", 3.0, "passed"),
        ("rotate_beside_wall", 1.0, "passed"),
        ("hidden 1", 3.0, "passed"),
    ]
    assert data["tests"][-1]["output"] == "passed"
    assert "score: 10 of 10" in stdout  # the autograder's stdout, for the instructor


def test_a_package_that_does_not_build_gets_0_and_why(autograder: Path) -> None:
    data, _ = grade(autograder, broken_setup_package)
    assert data["score"] == 0.0
    assert data["output"].startswith("not graded: did not build: setup.py line 18: SyntaxError")
    assert [t["status"] for t in data["tests"]] == ["failed"] * 5
    assert [t["name"] for t in data["tests"]][-1] == "hidden 1"


def test_an_empty_submission_gets_0_and_why(autograder: Path) -> None:
    data, _ = grade(autograder, None)
    assert data["score"] == 0.0
    assert data["output"] == "not graded: no node found: no package.xml and no .py file"


def test_without_the_harness_installed_a_results_json_still_says_why(autograder: Path) -> None:
    data, _ = grade(autograder, script_student, FOSSBOT_HIL_VENV=str(autograder / "nowhere"))
    assert data == {
        "score": 0.0,
        "output": "not graded: the autograder is not installed (its setup failed): "
        "tell your instructor",
        "tests": [],
    }


def test_setup_refuses_a_zip_without_fossbot_hil(tmp_path: Path) -> None:
    done = script(EXAMPLE / "setup.sh", environment(tmp_path))
    assert done.returncode == 1
    assert "put its release into the zip as fossbot-hil/" in done.stderr
