"""The plot's axes decorations, drawn once per set of limits and pasted back, look as
matplotlib draws them in place: the same pixels, but for rounding where the grid crosses
a failed-tick bar."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from harness.links.base import LinkOptions
from harness.report import plot
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario

STUDENTS = Path(__file__).parents[1] / "student_functions.py"


def pixels(png: bytes) -> np.ndarray:
    from matplotlib.image import imread

    return (imread(io.BytesIO(png)) * 255).round().astype(int)


def drawn_in_place(series: plot.PlotSeries) -> bytes:
    """The plot with each axis drawn by matplotlib where it stands, no layer."""
    canvas = plot._Canvas()
    canvas.layers.prepare = lambda _canvas: None  # type: ignore[method-assign]
    for layer in canvas.layers.layers:
        layer.set_visible(False)
    return canvas.draw(series)


def test_a_layered_plot_is_the_plot_matplotlib_draws() -> None:
    """A failing run: failed-tick bars under the grid, marks off the scale over the axes."""
    processor = f"{STUDENTS}:min_over_raw_ranges"
    [result] = run_suite(
        [resolve_scenario("drive_past_10m")], "inprocess", LinkOptions(processor=processor)
    )
    series = plot.plot_series(result)
    layered = plot.render_plot(series)
    assert plot.render_plot(series) == layered  # drawn from its kept layers: the same bytes
    difference = np.abs(pixels(layered) - pixels(drawn_in_place(series))).max(axis=2)
    assert difference.max() <= 1 and (difference > 0).sum() < 200
