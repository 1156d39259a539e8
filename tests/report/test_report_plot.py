"""The per-scenario plot: the series it draws, and the PNG it draws them into."""

from __future__ import annotations

import io
import math
import struct
from dataclasses import replace

import numpy as np

from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan
from harness.report.plot import FAILED_COLOUR, plot_series, render_plot, write_plot


def _scan(ranges: list[float]) -> Scan:
    n = len(ranges)
    return Scan(-math.pi, math.pi, 2 * math.pi / n, 0.0, 0.1, 0.12, 12.0, np.array(ranges))


def _tick(
    tick: int, sent: Scan, seen: Scan | None, status: str, warning: bool | None
) -> TickRecord:
    answers = Answers(
        statuses=[Received(status, 0.01)],
        warnings=[] if warning is None else [Received(warning, 0.01)],
        seen=seen,
    )
    verdict = Oracle(0.5).judge(tick, tick * 0.1, seen or sent, answers)
    return TickRecord(tick, tick * 0.1, 0.0, 0.0, 0.0, sent, answers, verdict)


def _colour_pixels(png: bytes, colour: str) -> int:
    from matplotlib.image import imread

    rgb = imread(io.BytesIO(png), format="png")[..., :3]
    want = np.array([int(colour[i : i + 2], 16) / 255 for i in (1, 3, 5)])
    return int(np.all(np.abs(rgb - want) < 2 / 255, axis=-1).sum())


def test_series_follow_the_judged_ticks(passing: RunResult, failing: RunResult) -> None:
    """Nearest valid range = the oracle's expected distance; flags match each verdict."""
    for result in (passing, failing):
        s = plot_series(result)
        records = result.records
        assert s.t.tolist() == [r.t for r in records]
        expected = [r.verdict.expected.distance for r in records]
        assert np.array_equal(s.nearest, np.array(expected, dtype=float), equal_nan=True)
        assert s.failed.tolist() == [not r.verdict.ok for r in records]
        assert s.warning_got.tolist() == [float(r.verdict.warning_got) for r in records]
        assert s.threshold == result.threshold
    s = plot_series(failing)
    # The failing node says "inf m" where nothing is in range: drawn off the scale.
    assert s.claimed_nonfinite.tolist() == s.failed.tolist()
    assert np.isnan(s.claimed[s.failed]).all() and np.isnan(s.nearest[s.failed]).all()
    assert "drive_past_10m" in s.title and "FAIL (19 of 136 ticks failed)" in s.title


def test_series_use_the_scan_the_node_saw() -> None:
    """Over a serial link the driver's scan (answers.seen) is what counts, not ours."""
    sent = _scan([1.0, 2.0, 3.0, 4.0])
    seen = _scan([0.4, math.inf, 0.05, math.nan])  # 0.05 is below range_min
    result = RunResult("s", "rplidar", 0, 0.5, "clean")
    result.records += [
        _tick(0, sent, seen, "Obstacle at 0.400 m, angle -3.142 rad", True),
        _tick(1, sent, None, "no obstacle", None),
    ]
    s = plot_series(result)
    assert s.nearest.tolist() == [np.float32(0.4), 1.0]
    assert s.claimed[0] == 0.4 and math.isnan(s.claimed[1])
    assert s.warning_expected.tolist() == [1.0, 0.0]
    assert math.isnan(s.warning_got[1])
    assert s.failed.tolist() == [False, True]


def test_plot_is_a_small_deterministic_png(passing: RunResult, failing: RunResult) -> None:
    """A real PNG of a readable size, a few tens of kB, the same bytes every time, whatever
    the process drew before (its one figure is redrawn for each plot)."""
    png = render_plot(plot_series(passing))
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png[16:24])
    assert 600 <= width <= 1000 and 300 <= height <= 600
    assert 10_000 < len(png) < 100_000
    assert b"Software" not in png and b"matplotlib" not in png
    assert render_plot(plot_series(failing)) != png  # other data, other legend entries
    assert render_plot(plot_series(passing)) == png


def test_failed_ticks_are_marked(passing: RunResult, failing: RunResult) -> None:
    """Failed ticks are shaded in the failure colour; a passing run has none of it."""
    assert _colour_pixels(render_plot(plot_series(passing)), FAILED_COLOUR) == 0
    assert _colour_pixels(render_plot(plot_series(failing)), FAILED_COLOUR) > 1000
    series = plot_series(passing)
    marked = series.failed.copy()
    marked[10:20] = True
    shaded = render_plot(replace(series, failed=marked))
    assert _colour_pixels(shaded, FAILED_COLOUR) > 1000


def test_write_plot_of_a_run_without_ticks(tmp_path) -> None:
    """A run that ended before its first tick still gives a (nearly empty) plot."""
    empty = RunResult("gone", "ros2", 0, 0.5, "clean", error="node exited with code 1")
    path = write_plot(tmp_path / "gone.png", empty)
    assert path.read_bytes()[:4] == b"\x89PNG"
    assert [p.name for p in tmp_path.iterdir()] == ["gone.png"]


def test_a_scenario_name_is_drawn_as_text_never_as_markup(tmp_path) -> None:
    """A name holding mathtext (`$\\foo$`) or control characters is drawn as it reads.

    It used to raise matplotlib's ParseFatalException out of `run --out`.
    """
    sent = _scan([1.0] * 36)
    result = RunResult("$\\foo$ \x1b[31m", "inprocess", 0, 0.5, "clean")
    result.records.append(_tick(0, sent, None, "Obstacle at 1.00 m, angle -3.14", False))
    path = write_plot(tmp_path / "plot.png", result)
    assert path.read_bytes().startswith(b"\x89PNG")
    assert "\\x1b" in plot_series(result).title


def test_the_angle_panel_shows_a_degrees_node_off_the_scale() -> None:
    """Expected and reported angles: right ones on the line whatever their wrap, degrees
    drawn off the scale (the gap an angle failure is about)."""
    scan = _scan([3.0, 0.5, 3.0, 3.0])  # nearest at beam 1: -pi/2
    result = RunResult("s", "ros2", 0, 0.3, "clean")
    result.records += [
        _tick(0, scan, None, "Obstacle at 0.500 m, angle -1.571 rad", False),
        _tick(1, scan, None, "Obstacle at 0.500 m, angle 4.712 rad", False),  # [0, 2 pi)
        _tick(2, scan, None, "Obstacle at 0.500 m, angle -90.0", False),  # degrees
        _tick(3, scan, None, "no obstacle", False),
    ]
    s = plot_series(result)
    assert np.allclose(s.angle_expected, -math.pi / 2)
    assert np.allclose(s.angle_claimed[:2], -math.pi / 2, atol=1e-3)
    assert math.isnan(s.angle_claimed[2]) and s.angle_off.tolist() == [False, False, True, False]
    assert math.isnan(s.angle_claimed[3])
    png = render_plot(s)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
