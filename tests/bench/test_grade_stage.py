"""The bench's grade stage: its class is what grade takes for script students, and one
real grade of it gives the per-student figure (speed is measured, never asserted)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.bench.figures import GRADE_KEYS, figures
from harness.bench.grade_class import NODE, make_class, measure_grade
from harness.bench.run import BenchPlan, parse_stages
from harness.grading.discover import discover


def test_each_student_of_the_class_is_a_script_student_with_the_lab_node(tmp_path: Path) -> None:
    scripts = make_class(tmp_path, 3)
    found = discover([tmp_path])
    assert [s.kind for s in found.students] == ["script"] * 3
    assert all(s.script is not None and s.script.name == NODE for s in found.students)
    assert all(s.problem is None for s in found.students)
    assert all((s.parent / "scan_logic.py").is_file() for s in scripts)
    assert "from .scan_logic" not in scripts[0].read_text()


def test_grade_is_a_stage_of_its_own() -> None:
    assert parse_stages("grade") == ("grade",)
    assert BenchPlan(quick=True).grade_students == 2


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(300)
def test_a_graded_class_gives_the_per_student_figure() -> None:
    stage = measure_grade(1, ("approach_wall",), runs=False)
    values = figures({"grade": stage}, 0.0)
    assert set(GRADE_KEYS) <= set(values)
    assert values["grade_students"] == 1
    assert values["grade_s"] > 0
    assert values["grade_per_student_s"] == pytest.approx(values["grade_s"])
    assert values["grade_runs_s"] is None and values["grade_ratio"] is None
    assert values["grade_runs_out_s"] is None and values["grade_ratio_out"] is None
