"""The CI templates of examples/ci/, run here against sample repositories.

Each template's shell steps run verbatim in a fresh virtual environment,
with the template's own variables, except two given for speed: SCENARIOS
is one scenario (the steps are the same for seven), and the course grades
one student. The fresh environment borrows the project's installed
packages through a .pth file (ci_template_steps.Machine): installing the
lock for real would download about 400 MB on every run, and what is
tested is that the template's steps and the lock work together, which
they must do here too: the lock step installs whatever pin the project's
environment lacks, and fossbot-hil itself is installed from a clone of
this working tree, as CI clones its release. The jobs share that
environment (as a self-hosted runner would), so only the first one
downloads what the project's environment lacks (today setuptools, wheel
and packaging, about 2 MB); each still runs its own install steps.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
import yaml
from ci_template_steps import (
    TEMPLATES,
    Machine,
    course_repository,
    harness_repository,
    load,
    play_github,
    play_gitlab,
    script_repository,
    workspace_repository,
)

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(400)]

FAST = {"SCENARIOS": "approach_wall"}  # one scenario instead of seven: the same steps


def harness_ref() -> str:
    """The fossbot-hil release every template names (they must agree)."""
    refs = set()
    for path in TEMPLATES.glob("*.yml"):
        data = load(path.name)
        refs.add(str(data.get("env", data.get("variables", {}))["FOSSBOT_HIL_REF"]))
    [ref] = refs
    return ref


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """This working tree as a git repository tagged with the templates' release."""
    return harness_repository(tmp_path_factory.mktemp("fossbot-hil"), harness_ref())


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Machine:
    """One CI runner's Python for the module: the first job's install steps install
    what the lock pins and the project's environment lacks; later jobs find it there."""
    return Machine.create(tmp_path_factory.mktemp("ci-python") / "venv")


def assert_full_report(report: Path) -> None:
    """The artifact holds what docs/ci.md promises: the page, the plot, the MCAP recording."""
    for name in ("index.html", "junit.xml", "scenarios/approach_wall.png"):
        assert (report / name).is_file(), f"the report has no {name}"
    assert (report / "scenarios" / "approach_wall.mcap").stat().st_size > 0


def test_templates_parse_and_agree() -> None:
    """Every template is YAML (what the CI services read), names the same release of
    fossbot-hil and installs it with the same hash-checked lines."""
    names = sorted(p.name for p in TEMPLATES.glob("*.yml"))
    assert names == ["github-course.yml", "github-student.yml", "gitlab-student.yml"]
    installs = set()
    for name in names:
        assert isinstance(yaml.safe_load((TEMPLATES / name).read_text()), dict)
        text = (TEMPLATES / name).read_text()
        installs.add(tuple(line.strip(" -") for line in text.splitlines() if "pip install" in line))
    [install] = installs
    assert any("--require-hashes" in line for line in install)
    harness_ref()


def test_github_student_workspace(tmp_path: Path, machine: Machine, harness: Path) -> None:
    """GitHub Actions, a student's colcon workspace: built, run, JUnit and report kept."""
    repo = workspace_repository(tmp_path / "student")
    play_github("github-student.yml", repo, machine, harness, FAST)
    summary = json.loads((repo / "report" / "summary.json").read_text())
    assert summary["ok"] and [e["scenario"] for e in summary["scenarios"]] == ["approach_wall"]
    assert (repo / "install" / "fossbot_lidar_processing").is_dir()  # colcon built it
    assert_full_report(repo / "report")


def test_gitlab_student_script(tmp_path: Path, machine: Machine, harness: Path) -> None:
    """GitLab CI, a student's node script: cloned release, pip cache where it is kept."""
    repo = script_repository(tmp_path / "student")
    given = {**FAST, "NODE": "python3 lidar_node.py", "FOSSBOT_HIL_REPOSITORY": harness.as_uri()}
    play_gitlab("gitlab-student.yml", repo, machine, given)
    summary = json.loads((repo / "report" / "summary.json").read_text())
    assert summary["ok"] and summary["scenarios"][0]["link"] == "ros2"
    assert not (repo / "install").exists()  # a script is not built
    assert_full_report(repo / "report")


def test_github_course_grades_every_submission(
    tmp_path: Path, machine: Machine, harness: Path
) -> None:
    """GitHub Actions, a course: every submission graded, the class table kept."""
    repo = course_repository(tmp_path / "course", ("alex",))
    play_github("github-course.yml", repo, machine, harness, {**FAST, "JOBS": "1"})
    with (repo / "grades" / "grades.csv").open(newline="") as table:
        [row] = list(csv.DictReader(table))
    assert (row["student"], row["approach_wall"], row["passed"]) == ("alex", "PASS", "1/1")
