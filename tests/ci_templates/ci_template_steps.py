"""Play the CI templates of examples/ci/ on this machine, step by step.

GitHub Actions and GitLab CI are not here, so what they do is played:
each shell step runs verbatim, with the shell and the variables the CI
service gives it, and each `uses:` step the templates name is stood in for
(checking out a repository, setting up Python, publishing JUnit, keeping an
artifact) with a check that what it needs is there. A step this file does
not know fails the test: a template cannot grow a step nobody runs.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from borrowed_venv import borrowing_venv

ROOT = Path(__file__).resolve().parents[2]
TEMPLATES = ROOT / "examples" / "ci"
LOCK = ROOT / "requirements" / "ci.txt"
STUDENT_NODE = ROOT / "tests" / "ros" / "student_node.py"
REFERENCE = ROOT / "node" / "fossbot_lidar_processing"
STEP_TIMEOUT_S = 240


def load(name: str) -> dict[str, Any]:
    """A template, parsed as the CI service would (YAML 1.1, `on:` stays a string key)."""
    text = (TEMPLATES / name).read_text()
    data = yaml.load(text, Loader=_Loader)  # noqa: S506 (a safe loader, see below)
    assert isinstance(data, dict), f"{name}: not a mapping"
    return data


class _Loader(yaml.SafeLoader):
    """SafeLoader without YAML 1.1's booleans from words: `on:` is a key, not True."""


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}


def lock_python() -> str:
    """The Python version requirements/ci.txt was compiled for ("3.11")."""
    found = re.search(r"pip-compile with Python (\d+\.\d+)", LOCK.read_text())
    assert found, f"{LOCK}: no 'pip-compile with Python X.Y' header"
    return found.group(1)


# -- the machine CI runs on ---------------------------------------------------------


@dataclass
class Machine:
    """A fresh virtual environment standing for the CI runner's Python.

    It sees the project's installed packages through a .pth file, so the
    lock step finds its pins installed instead of downloading 400 MB of
    wheels (what differs from the project's environment is installed for
    real, from the package index and pip's cache); their commands (colcon)
    come from the project's environment at the end of PATH. The ROS 2 wheels
    find their shared libraries through the LD_LIBRARY_PATH the project's
    interpreter set up (ros_wheels_bootstrapper), inherited from this one.
    """

    venv: Path

    @classmethod
    def create(cls, where: Path) -> Machine:
        return cls(borrowing_venv(where, "_ci_borrows_project.pth"))

    def environment(self, variables: Mapping[str, str]) -> dict[str, str]:
        """The process environment of a step: this machine's, then the CI's variables."""
        env = {
            k: v
            for k, v in os.environ.items()
            if not k.startswith(("PIP_", "PYTHON", "VIRTUAL_ENV", "ROS_", "COLCON", "AMENT"))
        }
        project_bin = str(Path(sys.executable).parent)
        env.update(
            PATH=os.pathsep.join([str(self.venv / "bin"), env.get("PATH", ""), project_bin]),
            VIRTUAL_ENV=str(self.venv),
            PIP_CONFIG_FILE=os.devnull,  # a CI runner has no pip configuration of this machine's
            PIP_DISABLE_PIP_VERSION_CHECK="1",
            CI="true",
        )
        env.update(variables)
        return env


def shell(
    script: str, *, cwd: Path, env: Mapping[str, str], argv: list[str]
) -> subprocess.CompletedProcess[str]:
    """Run one CI shell step; its output is the failure message if it fails."""
    done = subprocess.run(
        [*argv, "-c", script],
        cwd=cwd,
        env=dict(env),
        capture_output=True,
        text=True,
        timeout=STEP_TIMEOUT_S,
        check=False,
    )
    assert done.returncode == 0, (
        f"step failed ({done.returncode}):\n{script}\n{done.stdout[-4000:]}\n{done.stderr[-4000:]}"
    )
    return done


# -- what a template checks out --------------------------------------------------------


def harness_repository(where: Path, ref: str) -> Path:
    """A git repository holding this working tree (what the CI would clone), tagged `ref`."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
        timeout=60,
    ).stdout.decode()
    for name in filter(None, listed.split("\0")):
        source, target = ROOT / name, where / name
        if not source.is_symlink() and not source.is_file():
            continue  # deleted in the working tree
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target, follow_symlinks=False)
    git = {
        "GIT_AUTHOR_NAME": "ci",
        "GIT_AUTHOR_EMAIL": "ci@localhost",
        "GIT_COMMITTER_NAME": "ci",
        "GIT_COMMITTER_EMAIL": "ci@localhost",
        "GIT_CONFIG_GLOBAL": os.devnull,
        "GIT_CONFIG_NOSYSTEM": "1",
        "PATH": os.environ["PATH"],
    }
    for command in (
        ["git", "init", "--quiet"],
        ["git", "add", "--all"],
        ["git", "commit", "--quiet", "--no-verify", "-m", "the working tree"],
        ["git", "tag", ref],
    ):
        subprocess.run(command, cwd=where, env=git, check=True, timeout=120, capture_output=True)
    return where


def clone(repository: Path, ref: str, target: Path) -> None:
    """What `actions/checkout` with `repository:` and `ref:` leaves at `path:`."""
    subprocess.run(
        [
            "git",
            "clone",
            "--quiet",
            "--depth",
            "1",
            "--branch",
            ref,
            repository.as_uri(),
            str(target),
        ],
        check=True,
        timeout=120,
        capture_output=True,
    )


# -- sample repositories -------------------------------------------------------------


def script_node() -> str:
    """A correct Lab 07 node in one file, as a student without a package hands in."""
    source = STUDENT_NODE.read_text()
    chosen = 'variant = sys.argv[1] if len(sys.argv) > 1 else "correct"'
    assert chosen in source, f"{STUDENT_NODE} no longer chooses its variant that way"
    return source.replace(chosen, 'variant = "correct"')


def workspace_repository(where: Path) -> Path:
    """A student's repository that is a colcon workspace: src/<the lab's package>."""
    shutil.copytree(
        REFERENCE,
        where / "src" / REFERENCE.name,
        ignore=shutil.ignore_patterns(".ruff_cache", "__pycache__", "*.egg-info"),
    )
    return where


def script_repository(where: Path) -> Path:
    """A student's repository with one node script at its top."""
    where.mkdir(parents=True)
    (where / "lidar_node.py").write_text(script_node())
    return where


def course_repository(where: Path, students: tuple[str, ...]) -> Path:
    """A course's repository: submissions/<student>/lidar_node.py."""
    for student in students:
        folder = where / "submissions" / student
        folder.mkdir(parents=True)
        (folder / "lidar_node.py").write_text(script_node())
    return where


# -- checks standing in for the CI services' own steps -------------------------------


def check_junit(paths: list[Path]) -> None:
    """What a JUnit publisher reads: at least one file, each a parseable test suite."""
    assert paths, "no JUnit file to publish"
    for path in paths:
        root = ET.parse(path).getroot()
        assert root.tag in ("testsuites", "testsuite"), f"{path}: root <{root.tag}>"
        assert root.iter("testcase"), f"{path}: no test case"


def check_artifact(workspace: Path, path: str) -> None:
    """What an artifact upload keeps: the path exists and holds files."""
    found = workspace / path
    assert found.exists(), f"artifact {path} was not written"
    assert not found.is_dir() or any(p.is_file() for p in found.rglob("*")), f"{path} is empty"


# -- GitHub Actions -------------------------------------------------------------------

_EXPRESSION = re.compile(r"\$\{\{\s*(.*?)\s*\}\}")
ALWAYS = "${{ !cancelled() }}"  # the one condition the templates use: run after a failure too


def github_value(text: str, env: Mapping[str, str]) -> str:
    """`text` with each `${{ env.NAME }}` replaced; any other expression fails the test."""

    def value(found: re.Match[str]) -> str:
        name = found.group(1).removeprefix("env.")
        assert name != found.group(1) and name in env, f"unknown expression {found.group(0)}"
        return env[name]

    return _EXPRESSION.sub(value, text)


def _checkout(given: Mapping[str, str], workspace: Path, harness: Path) -> None:
    if "repository" not in given:
        assert workspace.is_dir()  # the repository the workflow runs in: the sample
        return
    clone(harness, given["ref"], workspace / given["path"])


def _setup_python(given: Mapping[str, str], workspace: Path, harness: Path) -> None:
    assert given["python-version"] == lock_python(), "the lock is for another Python"
    assert given["cache"] == "pip"
    key = list(workspace.glob(given["cache-dependency-path"]))
    assert key, f"pip's cache key file {given['cache-dependency-path']} is not there yet"


def _junit(given: Mapping[str, str], workspace: Path, harness: Path) -> None:
    check_junit(sorted(workspace.glob(given["report_paths"])))


def _artifact(given: Mapping[str, str], workspace: Path, harness: Path) -> None:
    check_artifact(workspace, given["path"])


ACTIONS = {
    "actions/checkout": _checkout,
    "actions/setup-python": _setup_python,
    "mikepenz/action-junit-report": _junit,
    "actions/upload-artifact": _artifact,
}


def play_github(
    name: str, workspace: Path, machine: Machine, harness: Path, overrides: Mapping[str, str]
) -> None:
    """Run the workflow's one job in `workspace`: each `run:` in its own bash, as the
    runner does (`bash --noprofile --norc -eo pipefail`), with the workflow's `env:`
    (then `overrides`); each `uses:` played by ACTIONS."""
    workflow = load(name)
    assert {"name", "on", "jobs"} <= set(workflow), f"{name}: not a workflow"
    [job] = workflow["jobs"].values()
    env = {k: str(v) for k, v in {**workflow.get("env", {}), **job.get("env", {})}.items()}
    env.update(overrides, GITHUB_WORKSPACE=str(workspace), GITHUB_ACTIONS="true")
    for step in job["steps"]:
        if "run" in step:
            assert "if" not in step, "a condition on a shell step is not played"
            variables = {
                **env,
                **{k: github_value(str(v), env) for k, v in step.get("env", {}).items()},
            }
            bash = ["bash", "--noprofile", "--norc", "-eo", "pipefail"]
            shell(step["run"], cwd=workspace, env=machine.environment(variables), argv=bash)
            continue
        action, _, version = step["uses"].partition("@")
        assert action in ACTIONS and version, f"{name}: no stand-in for {step['uses']}"
        assert step.get("if", ALWAYS) == ALWAYS, f"{name}: no stand-in for if: {step['if']}"
        given = {k: github_value(str(v), env) for k, v in step.get("with", {}).items()}
        ACTIONS[action](given, workspace, harness)


# -- GitLab CI --------------------------------------------------------------------------

GITLAB_KEYWORDS = {"variables", "stages", "default", "include", "workflow", "image", "cache"}


def _expand(text: str, variables: Mapping[str, str]) -> str:
    """GitLab's expansion of $NAME and ${NAME} in a variable or keyword's value."""
    return re.sub(
        r"\$\{(\w+)\}|\$(\w+)", lambda m: variables.get(m.group(1) or m.group(2), ""), text
    )


def play_gitlab(
    name: str, workspace: Path, machine: Machine, overrides: Mapping[str, str]
) -> dict[str, Any]:
    """Run the pipeline's one job in `workspace`: `before_script` and `script` in one
    shell (`sh -e`: the template must not need bash), with the `variables:` (then
    `overrides`) expanded as GitLab does; check its image, cache and artifacts.
    Returns the job, for more checks."""
    pipeline = load(name)
    jobs = [v for k, v in pipeline.items() if k not in GITLAB_KEYWORDS and not k.startswith(".")]
    [job] = jobs
    variables = {"CI": "true", "GITLAB_CI": "true", "CI_PROJECT_DIR": str(workspace)}
    for key, value in {**pipeline.get("variables", {}), **job.get("variables", {})}.items():
        variables[key] = _expand(str(value), variables)
    variables.update(overrides)
    image = re.fullmatch(r"python:(\d+\.\d+)(-\w+)?", job["image"])
    assert image and image.group(1) == lock_python(), (
        f"{job['image']}: the lock is for another Python"
    )
    cache = job["cache"]
    assert _expand(cache["key"], variables).strip("-"), "an empty cache key"
    cached = {str(workspace / p) for p in cache["paths"]}
    assert variables["PIP_CACHE_DIR"] in cached, "pip's cache folder is not the one cached"
    script = "\n".join([*job.get("before_script", []), *job["script"]])
    env = machine.environment(variables)
    shell(script, cwd=workspace, env=env, argv=["sh", "-e"])
    used = shell("python -m pip cache dir", cwd=workspace, env=env, argv=["sh", "-e"])
    assert used.stdout.strip() == variables["PIP_CACHE_DIR"], "pip caches somewhere else"
    artifacts = job["artifacts"]
    assert artifacts["when"] == "always", "keep the report of a failed run too"
    for path in artifacts["paths"]:
        check_artifact(workspace, path)
    check_junit(sorted(workspace.glob(artifacts["reports"]["junit"])))
    return job
