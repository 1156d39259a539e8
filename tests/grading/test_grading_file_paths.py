"""A grading file's scenario files may start with `~` or hold `$VAR`: no shell reads the file,
so the harness expands them as a shell would; an unset variable is one line naming the entry."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.cli import main
from harness.errors import ConfigError
from harness.grading.grading_file import load_grading_file

SHIPPED = Path(__file__).resolve().parents[2] / "harness" / "scenarios"


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """$HOME with hidden/wall.yaml; $COURSE a folder with other.yaml; a grading file elsewhere."""
    (tmp_path / "hidden").mkdir()
    (tmp_path / "hidden" / "wall.yaml").write_text((SHIPPED / "approach_wall.yaml").read_text())
    (tmp_path / "course").mkdir()
    (tmp_path / "course" / "other.yaml").write_text((SHIPPED / "out_of_range.yaml").read_text())
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("COURSE", str(tmp_path / "course"))
    (tmp_path / "elsewhere").mkdir()
    grading = tmp_path / "elsewhere" / "grading.yaml"
    grading.write_text(
        "scenarios:\n  - scenario: ~/hidden/wall.yaml\n    hidden: true\n"
        "  - ${COURSE}/other.yaml\npoints: 10\n"
    )
    return grading


def test_scenario_files_under_home_or_a_variable_are_found(course: Path) -> None:
    home = course.parents[1]
    first, second = load_grading_file(course).planned
    assert first.scenario == str(home / "hidden" / "wall.yaml")
    assert second.scenario == str(home / "course" / "other.yaml")


def test_a_run_with_that_grading_file_runs_those_scenarios(
    course: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`run --grading` (the autograder's way in) with the expanded files: scored, exit 0."""
    assert main(["run", "--grading", str(course), "--link", "inprocess"]) == 0
    out = capsys.readouterr().out
    assert "hidden 1" in out and "other" in out and "score: 10 of 10" in out, out


def test_an_unset_variable_names_the_entry(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("NOPE", raising=False)
    grading = tmp_path / "grading.yaml"
    grading.write_text("scenarios:\n  - approach_wall\n  - $NOPE/wall.yaml\n")
    with pytest.raises(ConfigError) as caught:
        load_grading_file(grading)
    assert str(caught.value) == (
        f"--grading {grading}: scenarios.1.scenario '$NOPE/wall.yaml': $NOPE is not set: set "
        "it (export NOPE=...), or write the value out"
    )
