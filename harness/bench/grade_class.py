"""Stage 'grade': what grading costs a student, beside what their own run costs.

A class of correct script students (the bundled node as a student hands it in:
``fossbot_lidar_node.py`` with its ``scan_logic.py`` beside it) is graded by
``fossbot-hil grade CLASS --no-audit`` on the embedded cluster (one worker per
core), from spawn to exit, the default suite; then the same students are run by
``fossbot-hil run --node "python3 .../fossbot_lidar_node.py"`` one after the other.
``grade_per_student_s`` is the grade's wall time over its students; ``grade_ratio``
is the grade's wall time over what the runs need on the cluster's workers (their
sum over the workers): 1.0 would be grading at the speed of the runs. A quick
bench grades two students on approach_wall and runs none.
"""

from __future__ import annotations

import csv
import subprocess
import tempfile
import time
from pathlib import Path

import harness
from harness.bench.stage import StageResult
from harness.bench.suite_commands import _fossbot_hil, cli_wall_s
from harness.cluster.client import default_workers
from harness.errors import HarnessError

GRADE_TIMEOUT_S = 300.0  # four students on the shipped suite take about 15 s on 2 cores
NODE = "fossbot_lidar_node.py"
RELATIVE_IMPORT = "from .scan_logic import"


def make_class(folder: Path, students: int) -> list[Path]:
    """`students` folders, each the bundled node as a script student hands it in."""
    source = Path(harness.__file__).resolve().parent / "reference"
    node = (source / "lidar_node.py").read_text(encoding="utf-8")
    if RELATIVE_IMPORT not in node:
        raise HarnessError(f"the bundled node no longer has {RELATIVE_IMPORT!r}")
    scripts = []
    for i in range(students):
        student = folder / f"student{i:02d}"
        student.mkdir(parents=True)
        (student / NODE).write_text(node.replace(RELATIVE_IMPORT, "from scan_logic import"))
        (student / "scan_logic.py").write_text((source / "scan_logic.py").read_text())
        scripts.append(student / NODE)
    return scripts


def grade_wall_s(classroom: Path, out: Path, scenarios: tuple[str, ...]) -> float:
    """`fossbot-hil grade CLASS --no-audit` from spawn to exit; every student must pass."""
    argv = [*_fossbot_hil(), "grade", str(classroom), "--out", str(out), "--no-audit"]
    argv += [f"--scenario={','.join(scenarios)}"] if scenarios else []
    started = time.perf_counter()
    try:
        done = subprocess.run(argv, capture_output=True, timeout=GRADE_TIMEOUT_S, check=False)
    except subprocess.TimeoutExpired:
        raise HarnessError(f"fossbot-hil grade took longer than {GRADE_TIMEOUT_S:g} s") from None
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).decode(errors="replace").strip()[-300:]
        raise HarnessError(f"fossbot-hil grade exited {done.returncode}: {tail}")
    with open(out / "grades.csv", encoding="utf-8", newline="") as table:
        failed = [r["student"] for r in csv.DictReader(table) if not _all_passed(r["passed"])]
    if failed:
        raise HarnessError(f"fossbot-hil grade: not all passed: {', '.join(failed)}")
    return seconds


def _all_passed(cell: str) -> bool:
    passed, _, of = cell.partition("/")
    return passed == of and passed.isdigit()


def measure_grade(students: int, scenarios: tuple[str, ...] = (), runs: bool = True) -> StageResult:
    """Grade the class once, then (`runs`) run its students back to back."""
    workers = default_workers()
    with tempfile.TemporaryDirectory(prefix="fossbot-hil-bench-grade-") as tmp:
        classroom = Path(tmp) / "class"
        scripts = make_class(classroom, students)
        grade_s = grade_wall_s(classroom, Path(tmp) / "grades", scenarios)
        run_walls = (
            [cli_wall_s(["--node", f"python3 {s}", *scenarios]) for s in scripts] if runs else []
        )
    runs_s = sum(run_walls) if run_walls else None
    extra: dict[str, float | int | str | None] = {
        "grade_students": students,
        "grade_workers": workers,
        "grade_s": grade_s,
        "grade_per_student_s": grade_s / students,
        "grade_runs_s": runs_s,
        "grade_ratio": grade_s / (runs_s / min(workers, students)) if runs_s else None,
    }
    return StageResult("grade", 0, grade_s, 0.0, extra)
