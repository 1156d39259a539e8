"""The pages the browser tests open, made by real commands, and where they are served.

Shared by conftest.py (the fixtures) and the test modules of this folder.
"""

from __future__ import annotations

import fcntl
import json
import shutil
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from command_line import COMMAND

REPO = Path(__file__).resolve().parents[2]
STUDENT_NODE = REPO / "tests" / "ros" / "student_node.py"
STUDENT_FUNCTIONS = REPO / "tests" / "student_functions.py"
# The pages' scenarios: two shipped ones with the same world, LIDAR, faults and topics,
# driven for a dozen ticks instead of 45 and 64 (a report's page is laid out the same,
# and its plots and animations drawn the same, whatever the length of the run).
SHORTENED: dict[str, tuple[str, dict[str, Any]]] = {  # name -> (shipped scenario, changes)
    "side_post": (  # obstacle_at_side, from 0.5 m before the post to 0.5 m past it
        "obstacle_at_side",
        {
            "robot": {"start": {"x": 0.5}},
            "motion": {"segments": [{"linear": 0.5, "until": {"distance": 1.0}}]},
        },
    ),
    "nothing_in_range": (  # out_of_range, turning one radian instead of a full turn
        "out_of_range",
        {"motion": {"segments": [{"angular": 1.0, "until": {"turn": 1.0}}]}},
    ),
}
SCENARIOS = tuple(SHORTENED)
STUDENTS = {"alice": "correct", "bob": "min_over_raw_ranges"}  # name -> student_node variant
WIDTH, HEIGHT = 1280, 800
BUILD_WAIT_S = 400  # the commands' own timeouts, and a wait for another worker's
WAIT_MS = 10_000  # every wait in the browser is bounded by this
# What Chromium needs on these machines: no sandbox as root, and nothing that
# reaches for the (closed) network on its own. Playwright adds --headless and a
# fresh --user-data-dir.
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@dataclass(frozen=True)
class Built:
    """A folder commands wrote, and what they said."""

    folder: Path
    returncodes: list[int]
    output: str


@dataclass(frozen=True)
class Server:
    """A localhost HTTP server whose root is the base temp folder the sites live in."""

    root: Path
    url: str

    def url_of(self, path: Path) -> str:
        return self.url + path.resolve().relative_to(self.root).as_posix()


def built_once(folder: Path, make: Callable[[Path], list[tuple[int, str]]]) -> Built:
    """`make(folder)`, run by the first worker to get here; the others wait for it (each
    command it runs is bounded) and read what it left."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    record = folder.with_name(folder.name + ".json")
    with open(folder.with_name(folder.name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not record.is_file():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            record.write_text(json.dumps(make(folder)))
    done = json.loads(record.read_text())
    return Built(folder, [code for code, _ in done], "\n".join(said for _, said in done))


def command(*args: str, cwd: Path, timeout: float) -> tuple[int, str]:
    """Run `fossbot-hil ARGS` in `cwd`: its exit code, and the command line with its
    output and how long it took (for a failure's message)."""
    started = time.monotonic()
    try:
        done = subprocess.run(
            [*COMMAND, *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
        )
        code, said = done.returncode, done.stdout + done.stderr
    except subprocess.TimeoutExpired as expired:
        code, said = -1, f"timed out after {timeout} s: {expired.stdout!r} {expired.stderr!r}"
    took = time.monotonic() - started
    return code, f"$ fossbot-hil {' '.join(args)}  ({took:.1f} s)\n{said}"


def scenario_files(folder: Path) -> list[str]:
    """SHORTENED's scenarios, written as scenario files into `folder`."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, (shipped, changes) in SHORTENED.items():
        data = yaml.safe_load((REPO / "scenarios" / f"{shipped}.yaml").read_text())
        data.update(changes, description=f"{shipped}, shortened: {data['description']}"[:200])
        path = folder / f"{name}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        paths.append(str(path))
    return paths


def make_run(folder: Path) -> list[tuple[int, str]]:
    """index.html of a run compared with a baseline (the widest table a run has):
    side_post passes, nothing_in_range fails (min over the raw ranges) and is new."""
    scenarios = scenario_files(folder / "scenario-files")
    inprocess = ("--link", "inprocess")
    baseline = command(
        "run", *inprocess, scenarios[0], "--out", "baseline", cwd=folder, timeout=120
    )
    processor = f"{STUDENT_FUNCTIONS}:min_over_raw_ranges"
    run = command(
        "run",
        *inprocess,
        *("--processor", processor, "--baseline", "baseline", "--animate"),
        *scenarios,
        *("--out", "run"),
        cwd=folder,
        timeout=150,
    )
    return [baseline, run]


def make_class(folder: Path) -> list[tuple[int, str]]:
    """grades.html and each student's report: alice is right, bob fails nothing_in_range.
    One Dask worker: the students one after the other, the same steps as at once."""
    scenarios = ",".join(scenario_files(folder / "scenario-files"))
    classroom = folder / "class"
    for name, variant in STUDENTS.items():
        (classroom / name).mkdir(parents=True)
        (classroom / name / "lidar_node.py").write_text(
            f"import sys\n\nsys.argv[1:1] = [{variant!r}]\n" + STUDENT_NODE.read_text()
        )
    options = ("--workers", "1", "--scenario", scenarios, "--no-audit")
    return [command("grade", "class", "--out", "grades", *options, cwd=folder, timeout=200)]


# What makes which pages (named as test_pages.py's PAGES names them).
BUILDS: dict[str, tuple[Callable[[Path], list[tuple[int, str]]], tuple[str, ...]]] = {
    "run": (make_run, ("index.html",)),
    "class": (make_class, ("grades.html", *(f"report of {name}" for name in STUDENTS))),
}
