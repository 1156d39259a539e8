"""A real run's report says which readings the suite delivered: summary.json and index.html."""

from __future__ import annotations

import json
from pathlib import Path

from harness.judge.reading_coverage import CASES, coverage_of
from harness.judge.records import RunResult
from harness.report.outputs import write_report

NAN_GAP = "no scan has NaN beside a valid return: a node that filters inf but not NaN passes"


def test_summary_and_page_carry_the_coverage(
    tmp_path: Path, passing: RunResult, failing: RunResult
) -> None:
    """approach_wall and drive_past_10m (inprocess): counts in total and per scenario,
    and the gaps, in summary.json and on the page."""
    write_report(tmp_path, [passing, failing], writers=[])
    summary = json.loads((tmp_path / "summary.json").read_text())
    coverage = summary["coverage"]
    assert list(coverage) == ["near_threshold_m", "angle_near_pi_rad", "total", "scenarios", "gaps"]
    total = coverage["total"]
    assert total == coverage_of([passing, failing]).as_dict()
    assert total["scans"] == len(passing.records) + len(failing.records)
    assert list(total["cases"]) == list(CASES)
    assert list(coverage["scenarios"]) == ["approach_wall", "drive_past_10m"]
    wall, away = coverage["scenarios"]["approach_wall"], coverage["scenarios"]["drive_past_10m"]
    assert wall["scans"] == len(passing.records)
    assert wall["cases"]["pos_inf"]["beside_valid"] == wall["scans"]  # one wall, inf elsewhere
    assert away["cases"]["pos_inf"]["without_valid"] > 0  # past 10 m: nothing in range
    assert away["warning_clears"] == 1  # starts near the wall, drives away
    assert NAN_GAP in coverage["gaps"]

    page = (tmp_path / "index.html").read_text()
    assert "<h2>Readings the suite delivered</h2>" in page
    section = page[page.index("Readings the suite delivered") :]
    assert f'<tr><td>+inf<td class="n">{total["cases"]["pos_inf"]["beside_valid"]}' in section
    assert "What the suite never delivered" in section
    assert NAN_GAP in section
