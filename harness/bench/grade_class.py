"""Stage 'grade': what grading costs a student, beside what their own run costs.

A class of correct script students (the bundled node as a student hands it in:
``fossbot_lidar_node.py`` with its ``scan_logic.py`` beside it) is graded by
``fossbot-hil grade CLASS --no-audit`` on the embedded cluster (one worker per
core), from spawn to exit, the default suite; then the same students are run by
``fossbot-hil run --node "python3 .../fossbot_lidar_node.py"`` one after the other.
Two classes are graded, the plan's (four students) and issue 41's eight, and
the eight are run, in three rounds that alternate the grades and the runs
(medians). ``grade_per_student_s`` is the eight's grade wall time over its
students; ``grade_ratio`` is that wall time over what the runs need on the
cluster's workers (their sum over the workers): 1.0 would be grading at the speed
of the runs (``grade4_*``: the same for the four). The eight are also run each
writing its report (``--out``, what grade writes for each student):
``grade_runs_out_s`` and ``grade_ratio_out`` set grade against runs doing the
same work. A quick bench grades two students on approach_wall once and runs none.
"""

from __future__ import annotations

import csv
import statistics
import tempfile
from collections.abc import Callable
from pathlib import Path

import harness
from harness.bench.stage import StageResult
from harness.bench.suite_commands import COMMAND_FLAGS, cli_args, cli_wall_s, spawn_s
from harness.cluster.client import default_workers
from harness.errors import HarnessError

GRADE_TIMEOUT_S = 300.0  # eight students on the shipped suite take about 30 s on 2 cores
DONE_WHEN_STUDENTS = 8  # issue 41's figure: 8 students graded on 2 cores against their runs
ROUNDS = 3  # grades and runs alternated, medians taken: the machine is shared
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
    argv = ["grade", str(classroom), *cli_args(out=str(out)), COMMAND_FLAGS["no_audit"]]
    argv += cli_args(scenario=",".join(scenarios)) if scenarios else []
    seconds = spawn_s(argv, "fossbot-hil grade", GRADE_TIMEOUT_S)
    with open(out / "grades.csv", encoding="utf-8", newline="") as table:
        failed = [r["student"] for r in csv.DictReader(table) if not _all_passed(r["passed"])]
    if failed:
        raise HarnessError(f"fossbot-hil grade: not all passed: {', '.join(failed)}")
    return seconds


def _all_passed(cell: str) -> bool:
    passed, _, of = cell.partition("/")
    return passed == of and passed.isdigit()


def measure_grade(
    students: int, scenarios: tuple[str, ...] = (), runs: bool = True, rounds: int = ROUNDS
) -> StageResult:
    """With `runs`: classes of `students` and of DONE_WHEN_STUDENTS graded, and the larger
    class's runs back to back, without and with their reports, alternating for `rounds`
    rounds (medians; the smaller class's runs are the first of them); without: one grade
    of `students`, no runs."""
    workers = default_workers()
    sizes = sorted({students, DONE_WHEN_STUDENTS}) if runs else [students]
    grades: dict[int, list[float]] = {n: [] for n in sizes}
    run_walls: list[list[float]] = []
    reported_walls: list[list[float]] = []  # the same runs, each writing its report
    with tempfile.TemporaryDirectory(prefix="fossbot-hil-bench-grade-") as tmp:
        classes = {n: Path(tmp) / f"class{n}" for n in sizes}
        scripts = {n: make_class(folder, n) for n, folder in classes.items()}
        largest = scripts[sizes[-1]]

        def grade_each() -> None:
            for n in sizes:
                grades[n].append(grade_wall_s(classes[n], Path(tmp) / f"grades{n}", scenarios))

        def runs_into(walls: list[list[float]], reports: Path | None) -> Callable[[], None]:
            def run_each() -> None:
                walls.append([cli_wall_s([*_run_args(s, reports), *scenarios]) for s in largest])

            return run_each

        reported = runs_into(reported_walls, Path(tmp) / "reports")
        steps = (grade_each, runs_into(run_walls, None), reported) if runs else (grade_each,)
        rounds = rounds if runs else 1
        for i in range(rounds):
            for step in steps if i % 2 == 0 else steps[::-1]:
                step()
    extra: dict[str, float | int | str | None] = {"grade_workers": workers, "grade_rounds": rounds}
    for n in sizes:
        grade_s = statistics.median(grades[n])
        runs_s = _median_of_sums(run_walls, n)
        reported_s = _median_of_sums(reported_walls, n)
        share = min(workers, n)
        prefix = "grade" if n == sizes[-1] else f"grade{n}"
        extra.update(
            {
                f"{prefix}_students": n,
                f"{prefix}_s": grade_s,
                f"{prefix}_per_student_s": grade_s / n,
                f"{prefix}_runs_s": runs_s,
                f"{prefix}_ratio": grade_s / (runs_s / share) if runs_s else None,
                f"{prefix}_runs_out_s": reported_s,
                f"{prefix}_ratio_out": grade_s / (reported_s / share) if reported_s else None,
            }
        )
    return StageResult("grade", 0, float(extra["grade_s"] or 0.0), 0.0, extra)


def _run_args(script: Path, reports: Path | None) -> list[str]:
    """`fossbot-hil run`'s arguments for a student's script, with its report under
    `reports` (a folder of the student's name) unless None."""
    if reports is None:
        return cli_args(node=f"python3 {script}")
    return cli_args(node=f"python3 {script}", out=str(reports / script.parent.name))


def _median_of_sums(rounds: list[list[float]], n: int) -> float | None:
    """The median over rounds of the first `n` runs' summed wall time (None: no runs)."""
    return statistics.median(sum(r[:n]) for r in rounds) if rounds else None
