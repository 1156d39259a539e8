"""`fossbot-hil grade` usage errors: exit 2, one line on stderr, nothing built or written."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.cli import main
from harness.runner import frame_memo


@pytest.fixture
def classroom(tmp_path: Path) -> Path:
    """A class folder with one (unbuilt) package student."""
    (tmp_path / "class" / "ana").mkdir(parents=True)
    (tmp_path / "class" / "ana" / "package.xml").write_text("<package/>")
    return tmp_path / "class"


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["{missing}"], "no such folder"),
        (["{empty}"], "no students found in"),
        (["{class}", "--workers", "0"], "workers must be a whole number 1..1000"),
        (["{class}", "--jobs", "0"], "argument --jobs: workers must be a whole number 1..1000"),
        (["{class}", "--workers", "2", "--scheduler", "tcp://h:1"], "--workers sizes the embedded"),
        (
            ["{class}", "--scheduler", "tcp://127.0.0.1:9"],
            "--scheduler tcp://127.0.0.1:9: cannot connect",
        ),
        (["{class}", "--scenario", "nope"], "unknown scenario 'nope'"),
        (["{class}", "--scenario", "approach_wall,approach_wall"], "given twice"),
        (["{class}", "--threshold", "-1"], "threshold must be a positive number"),
        (["{class}", "--build-timeout", "0"], "build timeout must be a positive number"),
        (["{class}", "--faults", "sparkles"], "sparkles"),
        (["{class}", "--status-regex", "(unclosed"], "regex"),
        (["{class}", "--node", "python3 x.py"], "--node does not apply to grade"),
        (["{class}", "--workspace", "ws"], "--workspace does not apply to grade"),
        (["{class}", "--domain-id", "3"], "--domain-id does not apply to grade"),
        (["{class}", "--link", "inprocess"], "grade runs students' nodes"),
        (["{class}", "--out", "{foreign}"], "not empty and not written by 'fossbot-hil grade'"),
        (["{class}", "--out", "{file}"], "not a folder"),
        ([], "the following arguments are required: DIR"),
        (["{class}", "--scenario", "examples/narrow_corridor.yaml"], "no such scenario file"),
        (["{class}", "--grading", "gradin.yaml"], "--grading gradin.yaml: no such grading file"),
        (["{class}", "--grading", "{grading}", "--scenario", "out_of_range"], "give one of them"),
        (["{class}", "--grading", "{bad_grading}"], "hidden/corridor.yaml: no such scenario file"),
        (["{class}", "--roster", "{bad_roster}"], "must name the columns folder and id"),
    ],
)
def test_usage_errors_exit_2_with_one_line(
    args: list[str],
    needle: str,
    classroom: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Bad input: exit 2, one line naming the problem, and no output folder made."""
    (tmp_path / "empty").mkdir()
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "thesis.tex").write_text("precious")
    (tmp_path / "file").write_text("x")
    (tmp_path / "grading.yaml").write_text("scenarios: [approach_wall]\n")
    (tmp_path / "course").mkdir()
    (tmp_path / "course" / "grading.yaml").write_text(
        "scenarios:\n  - scenario: hidden/corridor.yaml\n    hidden: true\n"
    )
    (tmp_path / "roster.csv").write_text("name,email\nana,a@b\n")
    places = {
        "{grading}": str(tmp_path / "grading.yaml"),
        "{bad_grading}": str(tmp_path / "course" / "grading.yaml"),
        "{bad_roster}": str(tmp_path / "roster.csv"),
        "{missing}": str(tmp_path / "missing"),
        "{empty}": str(tmp_path / "empty"),
        "{class}": str(classroom),
        "{foreign}": str(tmp_path / "foreign"),
        "{file}": str(tmp_path / "file"),
    }
    out = tmp_path / "grades"
    argv = ["grade", *(places.get(a, a) for a in args)]
    monkeypatch.chdir(tmp_path)  # a relative path is the instructor's, from where they are
    if "--out" not in args:
        argv += ["--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("fossbot-hil: error: "), err
    assert needle in err
    assert not out.exists()
    assert (tmp_path / "foreign" / "thesis.tex").read_text() == "precious"
    assert frame_memo._kept is None  # the tick counts' frames are not kept on in this process
