"""The alignment of the board's /scan in the reports: terminal, summary.json, index.html,
and `run --alignment fail`'s exit code; the device's gap between scenarios."""

from __future__ import annotations

import io
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

from harness.cli import main
from harness.judge.alignment import Alignment, run_alignment
from harness.judge.answers import Answers
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.mount import LidarMount
from harness.lidar.scan import Scan
from harness.report.outputs import ReportFolder
from harness.report.terminal import gap_line, print_results

V2 = LidarMount(yaw_deg=-90.0)
INC = 2 * math.pi / 360


def _truth(k: int) -> Scan:
    """An uneven scene: a near wall over 60 degrees, a far one over 30, nothing elsewhere."""
    ranges = np.full(360, np.inf)
    ranges[10:70] = np.linspace(0.8, 1.6, 60) + 0.01 * k
    ranges[200:230] = 2.5 - 0.02 * k
    return Scan(-math.pi, math.pi - INC, INC, 0.0, 0.1, 0.15, 12.0, ranges)


def _board(truth: Scan, turn: int) -> Scan:
    """The board's scan of `truth`: 360 bins over [0, 2 pi), turned by `turn` degrees."""
    shown = np.roll(truth.ranges, 180 + turn)  # truth bin 0 is at -180 degrees
    return Scan(0.0, 2 * math.pi - INC, INC, 0.0, 0.1, 0.15, 12.0, shown)


def _result(turn: int | None, *, name: str = "corner", gap_s: float | None = None) -> RunResult:
    """A passing run whose board showed the truth turned by `turn` (None: no board scans)."""
    records = []
    for k in range(5):
        truth = _truth(k)
        seen = None if turn is None else _board(truth, turn)
        answers = Answers(seen=seen)
        verdict = replace(Oracle(0.5).judge(k, 0.1 * k, seen or truth, answers), ok=True)
        records.append(TickRecord(k, 0.1 * k, 0.0, 0.0, 0.0, truth, answers, verdict))
    link = "inprocess" if turn is None else "rplidar"
    return RunResult(name, link, 0, 0.5, "clean", records=records, lidar_mount=V2, gap_s=gap_s)


def _fitted(turn: int) -> Alignment:
    alignment = run_alignment([_result(turn)])
    assert alignment is not None
    return alignment


def _printed(results: list[RunResult], alignment: Alignment | None, mode: str = "warn") -> str:
    out = io.StringIO()
    console = Console(file=out, width=400, color_system=None)
    print_results(console, results, alignment=alignment, alignment_mode=mode)
    return out.getvalue()


def _last_line(text: str) -> str:
    return text.rstrip("\n").split("\n")[-1]


def test_terminal_lines_aligned_misaligned_unknown() -> None:
    """One line at the end: quiet when aligned, a warning with the fix, or 'cannot tell'."""
    results = [_result(0)]
    aligned = _last_line(_printed(results, _fitted(0)))
    assert aligned == (
        "alignment: the board's /scan matches the robot's view "
        "(100 % of compared beams agree; 5 ticks)"
    )
    turned = _last_line(_printed(results, _fitted(90)))
    assert turned == (
        "alignment: WARNING: the board's /scan is the robot's view turned by +90 deg "
        "(100 % of compared beams agree so, 0 % as shown; 5 ticks): set the board driver's "
        "angle_offset_deg 90 deg lower (to -90 for the harness's mount: zero at -90 deg "
        "(to the right), clockwise), or if the board is right, run with --lidar-mount 0"
    )
    failed = _last_line(_printed(results, _fitted(90), mode="fail"))
    assert failed.startswith("alignment: FAILED (--alignment fail): the board's /scan is")
    unknown = replace(_fitted(0), status="unknown", reason="too little in range to compare")
    assert _last_line(_printed(results, unknown)) == (
        "alignment: cannot tell: too little in range to compare (5 ticks)"
    )
    assert "alignment:" not in _printed(results, None)


def test_gap_line_only_when_a_device_kept_streaming() -> None:
    """'between scenarios the device kept streaming: ...' under the table, when known."""
    assert gap_line([_result(0)]) == ""
    gaps = [_result(0, gap_s=None), _result(0, gap_s=0.82), _result(0, gap_s=1.2)]
    gaps.append(_result(0, gap_s=0.9))
    line = "between scenarios the device kept streaming: 0.8-1.2 s (median 0.9 s)"
    assert gap_line(gaps) == line
    assert line in _printed(gaps, None)
    assert gap_line([_result(0, gap_s=0.91)]) == (
        "between scenarios the device kept streaming: 0.9 s"
    )


def _report(tmp_path: Path, results: list[RunResult], **finish: object) -> tuple[dict, str]:
    with ReportFolder(tmp_path, writers=[]) as folder:
        for result in results:
            folder.add(result)
        index = folder.finish(**finish)  # type: ignore[arg-type]
    summary = json.loads((tmp_path / "summary.json").read_text())
    return summary, index.read_text()


def test_summary_and_page_hold_the_alignment(tmp_path: Path) -> None:
    """summary.json's `alignment` object; the page's section says the same words."""
    fitted = _fitted(90)
    summary, page = _report(tmp_path, [_result(90, gap_s=1.25)], alignment=fitted)
    assert summary["alignment"] == {
        "status": "misaligned",
        "rotation_deg": 90.0,
        "mirrored": False,
        "ticks": 5,
        "agreement": 1.0,
        "identity_agreement": fitted.identity_agreement,
        "fix": fitted.fix,
        "reason": "",
        "text": fitted.text(),
        "mode": "warn",
        "fails_run": False,
    }
    assert summary["ok"] is True  # a warning: the verdicts stand
    assert summary["scenarios"][0]["gap_s"] == 1.25
    assert "Alignment of the board" in page
    assert "WARNING: the board&#x27;s /scan is the robot&#x27;s view turned by +90 deg" in page
    assert "--lidar-mount 0" in page


def test_fail_mode_makes_the_summary_not_ok(tmp_path: Path) -> None:
    """With --alignment fail a misaligned board's /scan fails the run, as the exit code does."""
    summary, page = _report(tmp_path, [_result(90)], alignment=_fitted(90), alignment_mode="fail")
    assert summary["ok"] is False and summary["passed"] == 1
    assert summary["alignment"]["fails_run"] is True and summary["alignment"]["mode"] == "fail"
    assert 'class="misaligned fails"' in page and "FAILED (--alignment fail)" in page


def test_no_board_scans_is_null(tmp_path: Path) -> None:
    """The ros2 and inprocess links: `alignment` is null and the page has no section."""
    results = [_result(None)]
    assert run_alignment(results) is None
    summary, page = _report(tmp_path, results, alignment=run_alignment(results))
    assert summary["alignment"] is None and summary["ok"] is True
    assert summary["scenarios"][0]["gap_s"] is None
    assert "Alignment" not in page


@pytest.mark.parametrize(
    "turn,mode,code,line",
    [
        (90, "fail", 1, "alignment: FAILED (--alignment fail): the board's /scan is"),
        (90, "warn", 0, "alignment: WARNING: the board's /scan is"),
        (0, "fail", 0, "alignment: the board's /scan matches the robot's view"),
        (None, "fail", 0, None),
    ],
)
def test_run_alignment_fail_exit_code(
    turn: int | None,
    mode: str,
    code: int,
    line: str | None,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`run --alignment fail` exits 1 for a misaligned board's /scan, saying why; a warning,
    an aligned one or a link without board scans keep the verdicts' exit code."""
    result = _result(turn, name="approach_wall")
    monkeypatch.setattr("harness.runner.suite.run_suite", lambda *a, **k: [result])
    out = tmp_path / "report"
    argv = ["run", "approach_wall", "--link", "inprocess", "--alignment", mode, "--out", str(out)]
    assert main(argv) == code
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    if line is None:
        assert "alignment:" not in printed and summary["alignment"] is None
    else:
        assert line in printed
        assert summary["alignment"]["mode"] == mode
    assert summary["ok"] is (code == 0)


def test_alignment_option_is_checked(capsys: pytest.CaptureFixture[str]) -> None:
    """Only warn or fail: anything else is a usage error."""
    assert main(["run", "approach_wall", "--link", "inprocess", "--alignment", "maybe"]) == 2
    assert "--alignment: invalid choice: 'maybe'" in capsys.readouterr().err
