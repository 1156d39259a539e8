"""A campaign's plan and its results table: stable keys, durable rows, resume (pure)."""

from __future__ import annotations

from pathlib import Path

from harness.campaign.plan import SCENARIO_FAULTS, RunSpec, plan
from harness.campaign.results import ResultsTable, read_rows


def test_the_plan_is_every_combination_with_unique_keys() -> None:
    specs = plan(["a", "b"], [SCENARIO_FAULTS, "noisy"], [0, 1, 2], [None, 0.3])
    assert len(specs) == 2 * 2 * 3 * 2
    assert len({s.key for s in specs}) == len(specs)
    assert specs[0] == RunSpec("a", SCENARIO_FAULTS, 0, None)
    assert specs[0].key == "a|scenario|0|scenario"
    assert RunSpec("a", "noisy", 1, 0.3).as_row()["threshold"] == 0.3


def _row(spec: RunSpec, verdict: str = "PASS") -> dict[str, object]:
    return {**spec.as_row(), "verdict": verdict, "ticks": 10, "failed_ticks": 0}


def test_rows_are_written_as_they_come_and_read_back(tmp_path: Path) -> None:
    path = tmp_path / "out" / "results.csv"
    table = ResultsTable(path, resume=False)
    a, b = plan(["a", "b"], ["clean"], [0], [None])
    table.add(_row(a))
    assert [r["key"] for r in read_rows(path)] == [a.key]  # on disk at once
    table.add(_row(a, "FAIL"))  # a retried task finishing twice: still one row
    table.add(_row(b, "FAIL"))
    assert [(r["key"], r["verdict"]) for r in read_rows(path)] == [(a.key, "PASS"), (b.key, "FAIL")]


def test_resume_keeps_complete_rows_and_drops_a_row_cut_short(tmp_path: Path) -> None:
    path = tmp_path / "results.csv"
    table = ResultsTable(path, resume=False)
    a, b, c = plan(["a", "b", "c"], ["clean"], [0], [None])
    table.add(_row(a))
    table.add(_row(b))
    data = path.read_bytes()
    path.write_bytes(data[:-7])  # killed while writing b's row
    resumed = ResultsTable(path, resume=True)
    assert resumed.done == {a.key}
    resumed.add(_row(b))
    resumed.add(_row(c))
    assert [r["key"] for r in read_rows(path)] == [a.key, b.key, c.key]


def test_a_fresh_table_replaces_an_old_one(tmp_path: Path) -> None:
    path = tmp_path / "results.csv"
    ResultsTable(path, resume=False).add(_row(RunSpec("a", "clean", 0, None)))
    assert ResultsTable(path, resume=False).done == set()
    assert read_rows(path) == []
