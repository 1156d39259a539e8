"""A campaign's plan and its results table: stable keys, durable rows, resume (pure)."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.campaign.parquet import write_parquet
from harness.campaign.plan import SCENARIO_FAULTS, RunSpec, plan, variation_levels
from harness.campaign.results import ResultsTable, columns_for, read_rows
from harness.errors import ConfigError


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


def test_variations_multiply_the_plan_and_name_their_levels() -> None:
    variations = variation_levels({"wall_distance": [0.5, 1.0], "speed": [2.0]})
    specs = plan(["a"], [SCENARIO_FAULTS], [0], [None], variations)
    assert [s.key for s in specs] == [
        "a|scenario|0|scenario|wall_distance=0.5;speed=2.0",
        "a|scenario|0|scenario|wall_distance=1.0;speed=2.0",
    ]
    assert specs[0].as_row()["wall_distance"] == 0.5 and "variation" not in specs[0].as_row()
    assert plan(["a"], ["x"], [0], [None]) == plan(["a"], ["x"], [0], [None], variation_levels({}))


def test_variation_columns_follow_the_threshold_and_resume_needs_the_same(
    tmp_path: Path,
) -> None:
    path = tmp_path / "results.csv"
    columns = columns_for(["wall_distance"])
    assert columns[columns.index("threshold") + 1] == "wall_distance"
    table = ResultsTable(path, resume=False, columns=columns)
    (spec,) = plan(["a"], ["clean"], [0], [None], variation_levels({"wall_distance": [0.5]}))
    table.add(_row(spec))
    assert read_rows(path)[0]["wall_distance"] == "0.5"
    assert ResultsTable(path, resume=True, columns=columns).done == {spec.key}
    with pytest.raises(ConfigError, match="another --vary"):
        ResultsTable(path, resume=True)


def test_parquet_has_typed_columns(tmp_path: Path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    columns = columns_for(["speed"])
    rows = [
        {"key": "k1", "scenario": "a", "seed": "3", "threshold": "", "speed": "0.5"},
        {"key": "k2", "scenario": "a", "seed": "4", "threshold": "0.3", "speed": "2"},
    ]
    rows = [{**r, "verdict": "PASS", "ticks": "10", "wall_s": "1.25"} for r in rows]
    table = pq.read_table(write_parquet(tmp_path / "r.parquet", rows, columns)).to_pylist()
    typed = [(r["seed"], r["threshold"], r["speed"]) for r in table]
    assert typed == [(3, None, 0.5), (4, 0.3, 2.0)]
    assert table[0]["wall_s"] == 1.25 and table[0]["first_failure"] == ""
