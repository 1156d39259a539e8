"""`fossbot-hil run --out DIR`: the report folder from the command line."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from harness.cli import main

STUDENTS = Path(__file__).parents[1] / "student_functions.py"


def test_out_writes_the_report_of_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exit code, table, summary.json, plots and JUnit tell the same story."""
    out = tmp_path / "new" / "report"  # parents are created
    junit = tmp_path / "ci.xml"
    code = main(
        [
            "run",
            "approach_wall",
            "drive_past_10m",
            "--link",
            "inprocess",
            "--processor",
            f"{STUDENTS}:min_over_raw_ranges",
            "--out",
            str(out),
            "--junit-xml",
            str(junit),
        ]
    )
    captured = capsys.readouterr()
    assert code == 1, captured.out + captured.err
    assert f"report: {out / 'index.html'}" in captured.out
    assert "━" not in captured.out + captured.err  # no progress bar outside a terminal
    summary = json.loads((out / "summary.json").read_text())
    verdicts = {e["scenario"]: e["verdict"] for e in summary["scenarios"]}
    assert verdicts == {"approach_wall": "PASS", "drive_past_10m": "FAIL"}
    for entry in summary["scenarios"]:
        row = next(line for line in captured.out.splitlines() if line.startswith(entry["scenario"]))
        assert row.split()[2:5] == [str(entry["ticks"]), str(entry["failed"]), entry["verdict"]]
        assert (out / entry["files"]["plot"]).read_bytes()[:4] == b"\x89PNG"
        assert (out / entry["files"]["recording"]).read_bytes()[:5] == b"\x89MCAP"
    assert summary["scenarios"][1]["first_failure"] in captured.out
    # --junit-xml outside the folder still points at the plots, relative to itself.
    for xml in (out / "junit.xml", junit):
        for prop in ET.parse(xml).getroot().iter("property"):
            if prop.get("name") == "plot":
                assert (xml.parent / (prop.get("value") or "")).is_file()


@pytest.mark.parametrize("where", ["afile", "afile/sub"])
def test_out_that_is_not_a_folder_exits_2_before_running(
    where: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file in the way: exit 2, one line naming --out, and nothing ran."""
    (tmp_path / "afile").write_text("keep me")
    target = tmp_path / where
    assert main(["run", "approach_wall", "--link", "inprocess", "--out", str(target)]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1
    assert captured.err.startswith(f"fossbot-hil: error: --out {target}: ")
    assert captured.out == ""
    assert (tmp_path / "afile").read_text() == "keep me"
