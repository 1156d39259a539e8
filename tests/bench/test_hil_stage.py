"""The bench's hil stage: a real-time suite over the virtual board, its gaps read from
summary.json (speed is measured, never asserted)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from harness.bench.figures import HIL_KEYS, figures
from harness.bench.hil_board import QUICK_SUITE, hil_gaps, measure_hil
from harness.bench.run import parse_stages


def test_the_gaps_are_summary_jsons_after_the_first_scenario(tmp_path: Path) -> None:
    summary = tmp_path / "summary.json"
    entries = [{"gap_s": None}, {"gap_s": 0.5}, {"gap_s": 0.75}]
    summary.write_text(json.dumps({"scenarios": entries}))
    assert hil_gaps(summary) == [0.5, 0.75]


def test_hil_is_a_stage_of_its_own() -> None:
    assert parse_stages("hil") == ("hil",)
    assert len(QUICK_SUITE) == 2  # one gap


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(300)
def test_a_real_time_suite_gives_its_gap_figures() -> None:
    values = figures({"hil": measure_hil(QUICK_SUITE)}, 0.0)
    assert set(HIL_KEYS) <= set(values)
    assert values["hil_gaps"] == 1
    assert values["hil_suite_s"] > 0
    assert values["hil_gap_min_s"] == values["hil_gap_median_s"] == values["hil_gap_max_s"] >= 0
