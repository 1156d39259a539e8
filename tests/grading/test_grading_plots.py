"""grade's plots: left as data by the judging process, drawn by the worker's plotting process
into the student's report, the same PNG `run --out` draws; nothing else is written."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from harness.grading.plots import REQUEST_SUFFIX, PlotRequests, Plotter, draw_requested
from harness.grading.worker import run_job, write_job
from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.report.outputs import SCENARIO_FOLDER, ReportFolder
from harness.report.plot import plot_series, render_plot, series_data, series_from_data
from harness.runner.settings import RunSettings
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario

STUDENTS = Path(__file__).parents[1] / "student_functions.py"


@pytest.fixture(scope="module")
def failing() -> RunResult:
    """drive_past_10m against min(ranges): failed ticks, inf claims, NaN nearest ranges."""
    processor = f"{STUDENTS}:min_over_raw_ranges"
    [result] = run_suite(
        [resolve_scenario("drive_past_10m")], "inprocess", LinkOptions(processor=processor)
    )
    assert result.failed_ticks
    return result


def test_the_data_draws_the_same_png(failing: RunResult) -> None:
    """Through JSON and back (NaN as null), the series draws byte for byte the same plot."""
    series = plot_series(failing)
    data = json.loads(json.dumps(series_data(series), allow_nan=False))
    assert render_plot(series_from_data(data)) == render_plot(series)


def test_data_of_another_shape_is_refused(failing: RunResult) -> None:
    data = series_data(plot_series(failing))
    with pytest.raises(ValueError, match="differ in shape"):
        series_from_data({**data, "failed": data["failed"][:-1]})
    with pytest.raises(ValueError, match="not a plot's data"):
        series_from_data({k: v for k, v in data.items() if k != "t"})
    with pytest.raises(ValueError):
        series_from_data({**data, "t": ["x"] * len(data["t"])})


def test_the_report_names_the_plot_and_the_plotter_draws_it(
    failing: RunResult, tmp_path: Path
) -> None:
    """The report's plot writer leaves data in the grader's folder; the PNG the report
    names is drawn there by a Plotter, as `run --out` would have drawn it."""
    requests = tmp_path / "grader" / "plots"
    writers = [PlotRequests(requests).writer()]
    with ReportFolder(tmp_path / "report", writers) as report:
        files = report.add(failing)
        report.finish()
    png = tmp_path / "report" / SCENARIO_FOLDER / "drive_past_10m.png"
    assert files.paths["plot"] == png and not png.exists()
    assert [p.name for p in requests.iterdir()] == [f"drive_past_10m{REQUEST_SUFFIX}"]
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["scenarios"][0]["files"]["plot"] == "scenarios/drive_past_10m.png"
    plotter = Plotter()
    plotter.submit(requests, png.parent, tmp_path / "grader" / "plot-errors.log")
    assert plotter.wait_drawn(60.0)
    assert png.read_bytes() == render_plot(plot_series(failing))
    assert not (tmp_path / "grader" / "plot-errors.log").exists()


def test_a_bad_request_draws_nothing_and_is_logged(failing: RunResult, tmp_path: Path) -> None:
    """A file name with a path in it, or data that is not a plot's, writes no file."""
    requests, scenarios = tmp_path / "plots", tmp_path / "report" / "scenarios"
    requests.mkdir()
    scenarios.mkdir(parents=True)
    series = series_data(plot_series(failing))
    for name, png in (("escape", "../../outside.png"), ("junk", "junk.png")):
        data = {"png": png, "series": series if name == "escape" else {"t": [1]}}
        (requests / f"{name}{REQUEST_SUFFIX}").write_text(json.dumps(data))
    problems = draw_requested(requests, scenarios)
    assert len(problems) == 2 and "not a plot's file name" in problems[0]
    assert list(scenarios.iterdir()) == [] and not (tmp_path / "outside.png").exists()
    plotter = Plotter()
    log = tmp_path / "plot-errors.log"
    plotter.submit(requests, scenarios, log)
    assert plotter.wait_drawn(60.0)
    assert len(log.read_text().splitlines()) == 2


def test_the_plotting_process_draws_a_job(failing: RunResult, tmp_path: Path) -> None:
    """The plotter's process draws a student's plots and says so (its thread's part)."""
    requests, scenarios = tmp_path / "plots", tmp_path / "scenarios"
    scenarios.mkdir()
    PlotRequests(requests).leave(scenarios / "x.png", failing)
    plotter = Plotter()
    assert plotter._in_child((requests, scenarios, tmp_path / "log"))  # what its thread does
    assert (scenarios / "x.png").is_file()
    assert plotter.child_pid is not None and plotter.child_pid != os.getpid()


def test_a_job_with_plots_leaves_them_as_data(tmp_path: Path) -> None:
    """The judging process with `plots` in its job: every scenario's plot as data, no PNG."""
    job = write_job(
        tmp_path / "job.json",
        scenarios=["approach_wall"],
        link="inprocess",
        options=LinkOptions(),
        settings=RunSettings(),
        results=tmp_path / "results.json",
        junit=tmp_path / "junit.xml",
        report=tmp_path / "report",
        plots=tmp_path / "plots",
    )
    assert run_job(json.loads(job.read_text())) == 0
    assert [p.name for p in (tmp_path / "plots").iterdir()] == [f"approach_wall{REQUEST_SUFFIX}"]
    assert not list((tmp_path / "report").rglob("*.png"))
    assert draw_requested(tmp_path / "plots", tmp_path / "report" / SCENARIO_FOLDER) == []
    assert (tmp_path / "report" / SCENARIO_FOLDER / "approach_wall.png").is_file()
