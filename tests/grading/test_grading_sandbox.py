"""A class with a hostile hand-in, graded in the sandbox through the embedded cluster and
an external Dask scheduler: none of its attacks succeeds, the honest student's row is
that of an unsandboxed grading, and the hostile student gets a row that says what the
sandbox refused.

Real parts: bubblewrap, colcon building the hostile package (its setup.py runs), the
students' nodes over Fast DDS, a listener on the host's loopback, Dask.
"""

from __future__ import annotations

import csv
import json
import shutil
import socket
import subprocess
import threading
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
from cluster_nodes import variant_source
from command_line import COMMAND
from dask_cluster import GRADING_ENV, dask_cluster
from hostile_student import hostile_package, reports
from short_scenarios import NEAR_WALL, nothing_in_range

pytestmark = [
    pytest.mark.ros,
    pytest.mark.slow,
    pytest.mark.timeout(300),
]  # needs bubblewrap (`apt install bubblewrap`; .ci/run installs it): grade says so if not

HONEST_MARK = f"HONEST-{uuid.uuid4().hex[:8]}"  # in the honest student's node
SECRET_MARK = f"SECRET-{uuid.uuid4().hex[:8]}"  # in the hidden scenario file
HIDDEN_NAME = "secret_corridor"
LEFTOVER = f"hostile-leftover-{uuid.uuid4().hex[:8]}"
# One honest student, who fails the wall (degrees) and passes the hidden scenario: a
# FAIL with its explanation and a PASS, to match the unsandboxed grading.
HONEST = {"ben": "angle_in_degrees"}
VISIBLE = "near_wall"
SANDBOX_MB = 1024
GRADE = ["grade", "class", "--grading", "course/grading.yaml", "--no-audit"]
GRADE += ["--ready-timeout", "20", "--timeout", "5", "--sandbox-memory", str(SANDBOX_MB)]


class Listener:
    """A TCP listener on the host's 127.0.0.1 that counts who connects."""

    def __init__(self) -> None:
        self.socket = socket.create_server(("127.0.0.1", 0))
        self.port = self.socket.getsockname()[1]
        self.connections = 0
        self.socket.settimeout(0.2)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, daemon=True)
        self._thread.start()

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                connection, _ = self.socket.accept()
            except OSError:
                continue
            self.connections += 1
            connection.close()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.socket.close()


@pytest.fixture(scope="module")
def listener() -> Iterator[Listener]:
    opened = Listener()
    yield opened
    opened.close()


def make_course(root: Path, listener: Listener, *, hostile: bool) -> Path:
    """class/ (ben and maybe eve, the hostile one), course/grading.yaml with a short
    wall approach and a hidden scenario in course/hidden/ (out_of_range, a sixth of its
    turn)."""
    for name, variant in HONEST.items():
        (root / "class" / name).mkdir(parents=True)
        source = f"# {HONEST_MARK}\n" + variant_source(variant)
        (root / "class" / name / "lidar_node.py").write_text(source)
    hidden = root / "course" / "hidden" / f"{HIDDEN_NAME}.yaml"
    hidden.parent.mkdir(parents=True)
    hidden.write_text(f"# {SECRET_MARK}\n" + nothing_in_range())
    (root / "course" / f"{VISIBLE}.yaml").write_text(NEAR_WALL)
    (root / "course" / "grading.yaml").write_text(
        f"scenarios:\n  - {VISIBLE}.yaml\n"
        f"  - scenario: hidden/{HIDDEN_NAME}.yaml\n    hidden: true\n"
    )
    if hostile:
        out = root / "grades"
        targets = {
            "secrets": [HONEST_MARK, SECRET_MARK],
            "read": [str(root / "class" / "ben" / "lidar_node.py"), str(hidden)],
            "write": [
                str(out / "grades.csv"),
                str(out / "students" / "ben" / "junit.xml"),
                str(root / "class" / "ben" / "lidar_node.py"),
                str(hidden),
            ],
            # its own build, and the worker's slot, which holds only eve's while eve runs
            "own": [
                str(root / "class" / "eve"),
                str(out / "students" / "eve"),
                str(out / "grader" / ".slots"),
            ],
            "port": listener.port,
            "leftover": LEFTOVER,
            "alloc_mb": 8 * SANDBOX_MB,
        }
        hostile_package(root / "class" / "eve", targets)
    return root


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def grade(root: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    done = subprocess.run(
        [*COMMAND, *GRADE, "--out", "grades", *extra],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return done


def rows(out: Path) -> dict[str, dict[str, str]]:
    with open(out / "grades.csv", encoding="utf-8", newline="") as handle:
        return {row["student"]: row for row in csv.DictReader(handle)}


def leftovers() -> list[int]:
    """Processes anywhere on the machine that the hostile hand-in meant to leave behind."""
    found = []
    for proc in Path("/proc").iterdir():
        if proc.name.isdigit():
            try:
                if LEFTOVER.encode() in (proc / "cmdline").read_bytes():
                    found.append(int(proc.name))
            except OSError:
                continue
    return found


def check_contained(root: Path, before: dict[str, bytes], listener_connections: int) -> None:
    """Nothing the hostile hand-in tried got through."""
    out = root / "grades"
    assert listener_connections == 0, "the sandbox let a connection reach the host"
    assert snapshot(root / "class") == before["class"]
    assert snapshot(root / "course") == before["course"]
    assert not leftovers(), "a process of the hand-in outlived its sandbox"
    for path in out.rglob("*"):
        if path.is_file() and path.suffix in (".csv", ".xml", ".html", ".json", ".log"):
            text = path.read_text(errors="replace")
            assert "hacked" not in text, path
            if "students" in path.parts:  # the students' own files
                assert SECRET_MARK not in text and HIDDEN_NAME not in text, path
                assert HONEST_MARK not in text or path.parts[-3:-1] != ("students", "eve"), path
    build = reports((out / "students" / "eve" / "build.log").read_text(errors="replace"), "build")
    results = json.loads((out / "grader" / "eve" / "results.json").read_text())
    node = reports(json.dumps(results, indent=1).encode().decode("unicode_escape"), "node")
    assert build and node, "the hostile hand-in's attacks did not run"
    for said in (*build, *node):
        # (what it "wrote" went to the sandbox's own /tmp: the real files are checked above)
        assert said["found"] == [] and said["read"] == [], said
        assert said["connected"] != True, said  # noqa: E712  (True: it reached the host)
        assert said["alloc"] == "MemoryError", said


@pytest.fixture(scope="module")
def unsandboxed(tmp_path_factory: pytest.TempPathFactory, listener: Listener) -> dict:
    """The honest student alone, graded without the sandbox: the row to match."""
    root = make_course(tmp_path_factory.mktemp("plain"), listener, hostile=False)
    done = grade(root, "--no-sandbox", "--workers", "1")  # one student: one worker
    assert "warning: --no-sandbox" in done.stdout
    return rows(root / "grades")


def check_rows(table: dict[str, dict[str, str]], unsandboxed: dict[str, dict[str, str]]) -> None:
    assert sorted(table) == ["ben", "eve"]
    for name in HONEST:
        for column in (VISIBLE, HIDDEN_NAME, "passed", "first_failure", "score"):
            assert table[name][column] == unsandboxed[name][column], (name, column)
    eve = table["eve"]
    assert eve[VISIBLE] == "ERROR", eve
    assert "Read-only file system" in eve["first_failure"], eve
    assert "(the sandbox refused a write outside the student's own folders)" in eve["first_failure"]
    assert str(Path("/tmp")) + "/pytest" not in eve["first_failure"], eve  # no instructor path


def test_embedded_cluster_contains_the_hostile_hand_in(
    tmp_path: Path, listener: Listener, unsandboxed: dict
) -> None:
    root = make_course(tmp_path, listener, hostile=True)
    before = {"class": snapshot(root / "class"), "course": snapshot(root / "course")}
    done = grade(root)
    said = f"each student in a bubblewrap sandbox: {SANDBOX_MB} MB of memory per process"
    assert said in done.stdout
    check_rows(rows(root / "grades"), unsandboxed)
    check_contained(root, before, listener.connections)


def test_external_cluster_contains_the_hostile_hand_in(
    tmp_path: Path, listener: Listener, unsandboxed: dict
) -> None:
    root = make_course(tmp_path, listener, hostile=True)
    before = {"class": snapshot(root / "class"), "course": snapshot(root / "course")}
    with dask_cluster(1, nanny=True, env=GRADING_ENV) as (address, _):
        grade(root, "--scheduler", address)
    check_rows(rows(root / "grades"), unsandboxed)
    check_contained(root, before, listener.connections)
    shutil.rmtree(root / "grades", ignore_errors=True)


def test_an_external_cluster_whose_workers_cannot_sandbox_is_refused(tmp_path: Path) -> None:
    """Workers without bubblewrap (here: none on their PATH) are named, never used
    silently: with no worker able to sandbox, grade exits 2 before any student runs."""
    (tmp_path / "class" / "ana").mkdir(parents=True)
    (tmp_path / "class" / "ana" / "lidar_node.py").write_text(variant_source("correct"))
    with dask_cluster(1, nanny=False, env={**GRADING_ENV, "PATH": str(tmp_path)}) as (address, _):
        done = subprocess.run(
            [*COMMAND, "grade", "class", "--scenario", "approach_wall", "--no-audit"]
            + ["--scheduler", address],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=120,
        )
    assert done.returncode == 2, done.stdout + done.stderr
    assert "bwrap is not installed on " in done.stderr and "--no-sandbox" in done.stderr
    assert not (tmp_path / "grades" / "students").exists()
