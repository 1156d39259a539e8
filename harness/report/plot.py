"""One PNG per scenario: what the node saw, what it said, and where it went wrong.

Two steps so each can be checked on its own: ``plot_series`` turns a run
into plain arrays (pure numpy), ``render_plot`` draws them. matplotlib is
imported only when drawing (Agg, no display), so commands that never plot
stay quick to start.
"""

from __future__ import annotations

import io
import math
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from harness.atomic_write import write_atomically
from harness.judge.oracle import wrap
from harness.judge.records import RunResult
from harness.judge.verdicts import verdict_of
from harness.lidar.scan import Scan
from harness.safe_text import visible

__all__ = [
    "AS_WRITTEN", "PlotSeries", "draw_text", "plot_series", "prepare_canvas", "render_plot",
    "write_plot",
]  # fmt: skip

WIDTH_IN, HEIGHT_IN, DPI = 8.0, 6.0, 90  # about 720 x 540 px: a few tens of kB
# Where the axes sit, as fractions of the figure: room for the tick labels on the left,
# the title above and up to three rows of legend below.
MARGINS = {"left": 0.085, "right": 0.985, "top": 0.945, "bottom": 0.215, "hspace": 0.12}
ANGLE_REACH = 2 * math.pi + 0.1  # the oracle accepts angles in [-2 pi, 2 pi]; beyond: off scale
FAILED_COLOUR = "#f2b8b8"
# zlib level 3, not Pillow's 6: a third of the time to encode (9 against 24 ms), 11 % larger.
PNG_FAST = {"compress_level": 3}
# matplotlib text properties for text from outside (a scenario name, a node's status):
# mathtext off, so a "$" in it is a dollar sign, never a formula matplotlib fails to parse.
AS_WRITTEN: dict[str, Any] = {"parse_math": False}


def draw_text(where: Any, x: float, y: float, text: str, **style: Any) -> Any:
    """Draw text from outside on a Figure or Axes as written: non-printable characters
    as their escapes (`visible`), mathtext off (`AS_WRITTEN`). Returns the Text, whose
    later `set_text` calls keep mathtext off (their text must be made `visible` too)."""
    return where.text(x, y, visible(text), **AS_WRITTEN, **style)


@dataclass(frozen=True)
class PlotSeries:
    """Per-tick arrays, all the same length; NaN marks "nothing to draw here"."""

    title: str
    threshold: float
    t: np.ndarray  # simulated time of each scan, s
    nearest: np.ndarray  # min valid range of the scan the node saw (NaN: no valid reading)
    claimed: np.ndarray  # the node's distance (NaN: none given, or not finite)
    claimed_nonfinite: np.ndarray  # bool: the status gave inf or nan as the distance
    angle_expected: np.ndarray  # rad, in [-pi, pi) (NaN: no obstacle)
    angle_claimed: np.ndarray  # the node's angle on the expected one's turn (NaN: none)
    angle_off: np.ndarray  # bool: the node's angle is beyond +-2 pi (degrees?) or not finite
    warning_expected: np.ndarray  # 1 True, 0 False, NaN either (within the band)
    warning_got: np.ndarray  # 1 True, 0 False, NaN no Bool
    failed: np.ndarray  # bool
    not_delivered: np.ndarray  # bool: a link fault dropped it, or the line lost it


def _nearest_valid(scan: Scan) -> float:
    """The smallest valid reading (REP-117), else NaN."""
    valid = scan.valid_mask()
    return float(scan.ranges[valid].min()) if valid.any() else math.nan


def _flag(value: bool | None) -> float:
    return math.nan if value is None else float(value)


def _angles(expected: float | None, claimed: float | None) -> tuple[float, float, bool]:
    """(expected, claimed, off the scale): the claim is drawn on the expected angle's turn,
    so a node answering in [0, 2 pi) lies on the line when it is right; a claim the oracle
    never reads as radians (beyond +-2 pi, degrees most likely) is drawn off the scale."""
    want = math.nan if expected is None else wrap(expected)
    if claimed is None:
        return want, math.nan, False
    if not math.isfinite(claimed) or abs(claimed) > ANGLE_REACH:
        return want, math.nan, True
    base = want if math.isfinite(want) else 0.0
    return want, base + wrap(claimed - base), False


def plot_series(result: RunResult) -> PlotSeries:
    """The arrays a plot of `result` shows (the scan judged is the one the node saw)."""
    nearest, claimed, odd = [], [], []
    angles: list[tuple[float, float, bool]] = []
    # In time order: a reordered scan was judged after the next one.
    records = sorted(result.records, key=lambda r: r.t)
    for r in records:
        seen = r.answers.seen if r.answers.seen is not None else r.scan
        nearest.append(_nearest_valid(seen))
        claim = r.verdict.claim
        d = claim.distance if claim is not None and claim.obstacle else None
        finite = d is not None and math.isfinite(d)
        claimed.append(d if finite else math.nan)
        odd.append(d is not None and not finite)
        told = claim.angle if claim is not None and claim.obstacle else None
        angles.append(_angles(r.verdict.expected.angle, told))
    failed = len(result.failed_ticks)
    counted = f"{failed} of {len(records)} ticks failed" if failed else f"{len(records)} ticks"
    title = f"{visible(result.scenario)} · {result.link} · {verdict_of(result)} ({counted})"
    return PlotSeries(
        title=title,
        threshold=float(result.threshold),
        t=np.array([r.t for r in records], dtype=float),
        nearest=np.array(nearest, dtype=float),
        claimed=np.array(claimed, dtype=float),
        claimed_nonfinite=np.array(odd, dtype=bool),
        angle_expected=np.array([a[0] for a in angles], dtype=float),
        angle_claimed=np.array([a[1] for a in angles], dtype=float),
        angle_off=np.array([a[2] for a in angles], dtype=bool),
        warning_expected=np.array([_flag(r.verdict.expected.warning) for r in records]),
        warning_got=np.array([_flag(r.verdict.warning_got) for r in records]),
        failed=np.array([not r.verdict.ok for r in records], dtype=bool),
        not_delivered=np.array(
            [not r.delivery.delivered or r.answers.lost is not None for r in records], dtype=bool
        ),
    )


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end] index pairs of the consecutive True stretches in `mask`."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(int(a), int(b)) for a, b in zip(starts, ends, strict=True)]


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """(x, width) bars covering each stretch of ticks, half a tick either side."""
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.1
    return [(t[a] - step / 2, t[b] - t[a] + step) for a, b in _runs(mask)]


def _unwrapped_gaps(t: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The line broken where it wraps from pi to -pi, instead of a vertical stroke."""
    jumps = np.flatnonzero(np.abs(np.diff(angle)) > math.pi) + 1
    return np.insert(t, jumps, np.nan), np.insert(angle, jumps, np.nan)


class _Canvas:
    """One figure per process, its artists' data replaced for each plot: building the
    figure, its axes and their ticks anew cost two thirds of every plot's time. Every
    property a plot sets is set for each plot, so a PNG depends on its series only."""

    def __init__(self) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure  # lazy: matplotlib takes a while to import

        from harness.report.axis_layers import AxisLayers

        # Fixed margins, not a layout engine: "constrained" measured every text to place
        # the axes and cost 40 % of the plot's time, paid for every scenario of every report.
        self.fig = fig = Figure(figsize=(WIDTH_IN, HEIGHT_IN), dpi=DPI)
        self.canvas = FigureCanvasAgg(fig)
        self.axes = top, middle, bottom = fig.subplots(
            3, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2, 1], **MARGINS}
        )
        self.title = fig.suptitle("", fontsize=10, **AS_WRITTEN)  # a name may hold "$"
        self.failed = [self._spans(ax, FAILED_COLOUR) for ax in self.axes]
        for ax in self.axes:
            ax.grid(True, lw=0.4, alpha=0.5)
            ax.tick_params(labelsize=8)
        self.band = self._spans(bottom, "#dddddd")
        marker = {"ms": 2.5, "color": "#e07b00"}
        off_scale = {"ms": 4, "color": "#e07b00", "clip_on": False}
        # Each line with its legend entry; an entry is shown while its line has data.
        (self.nearest,) = top.plot([], [], color="#1f5fa8", lw=1.4)
        self.threshold = top.axhline(0.0, color="#555555", ls="--", lw=1)
        (self.claimed,) = top.plot([], [], "o", **marker)
        (self.above,) = top.plot([], [], "^", **off_scale)
        (self.gone,) = top.plot([], [], "x", ms=4, color="#777777", clip_on=False)
        (self.failed_key,) = top.plot([], [], "s", color=FAILED_COLOUR)
        top.set_ylabel("range, m", fontsize=8)
        centred = {"ha": "center", "va": "center", "fontsize": 9}
        self.note = top.text(0.5, 0.5, "", transform=top.transAxes, **centred)
        (self.angle,) = middle.plot([], [], color="#1f5fa8", lw=1.4)
        (self.angle_claimed,) = middle.plot([], [], "o", **marker)
        (self.angle_off,) = middle.plot([], [], "^", **off_scale)
        middle.set_ylim(-4.0, 4.0)
        middle.set_yticks([-math.pi, 0, math.pi], ["-pi", "0", "pi"])
        middle.set_ylabel("angle, rad", fontsize=8)
        (self.expected,) = bottom.step([], [], where="mid", color="#2e8b57", lw=3, alpha=0.45)
        (self.got,) = bottom.plot([], [], "o", ms=2.5, color="#222222")
        (self.band_key,) = bottom.plot([], [], "s", color="#dddddd")
        bottom.set_ylim(-0.3, 1.3)
        bottom.set_yticks([0, 1], ["False", "True"])
        bottom.set_ylabel("warning", fontsize=8)
        bottom.set_xlabel("simulated time, s", fontsize=8)
        self.keys = [
            (self.nearest, "nearest valid return (seen)"),
            (self.threshold, "threshold"),
            (self.claimed, "node's distance"),
            (self.above, "node's distance off the scale (or inf/nan)"),
            (self.gone, "scan not delivered (link fault)"),
            (self.failed_key, "failed tick"),
            (self.angle, "expected angle"),
            (self.angle_claimed, "node's angle"),
            (self.angle_off, "node's angle beyond 2 pi (degrees?) or inf/nan"),
            (self.expected, "warning expected"),
            (self.got, "warning received"),
            (self.band_key, "warning either accepted"),
        ]
        self.layers = AxisLayers(self.axes)  # the axes' ticks and grid, once per set of limits
        # The figure without its axes and title, one per set of legend entries shown: the
        # legend is the same picture each time and took a quarter of the plot's time.
        self.backgrounds: dict[tuple[str, ...], Any] = {}

    @staticmethod
    def _spans(ax: Any, colour: str) -> Any:
        """Bars the full height of `ax` (x in data, y in axes units), drawn by `draw`."""
        return ax.broken_barh([], (0, 1), transform=ax.get_xaxis_transform(), color=colour, lw=0)

    def _background(self, shown: set[Any]) -> Any:
        """The figure's pixels with only the legend of the `shown` lines drawn."""
        from matplotlib.legend import Legend

        keys = [(line, label) for line, label in self.keys if line in shown]
        labels = tuple(label for _, label in keys)
        if labels not in self.backgrounds:
            style = {"loc": "lower center", "ncols": 4, "fontsize": 7, "frameon": False}
            self.fig.legends[:] = [Legend(self.fig, [k for k, _ in keys], list(labels), **style)]
            try:
                for artist in (*self.axes, self.title):
                    artist.set_visible(False)
                self.canvas.draw()
                self.backgrounds[labels] = self.canvas.copy_from_bbox(self.fig.bbox)
            finally:
                for artist in (*self.axes, self.title):
                    artist.set_visible(True)
        return self.backgrounds[labels]

    def draw(self, series: PlotSeries) -> bytes:
        """The PNG bytes of `series` (deterministic: no software or date in the metadata)."""
        from matplotlib.image import imsave

        top, middle, bottom = self.axes
        t = series.t
        self.title.set_text(series.title)
        step = float(np.median(np.diff(t))) if t.size > 1 else 0.1
        failed = _bars(_spans(t, series.failed))
        for bars in self.failed:
            bars.set_verts(failed)
        band = _spans(t, np.isnan(series.warning_expected))
        self.band.set_verts(_bars(band))

        finite = np.concatenate([series.nearest[np.isfinite(series.nearest)], [series.threshold]])
        ceiling = 1.15 * float(finite.max())
        top.set_ylim(0, ceiling)
        self.nearest.set_data(t, series.nearest)
        self.threshold.set_ydata([series.threshold] * 2)
        shown = np.isfinite(series.claimed) & (series.claimed <= ceiling)
        above = (np.isfinite(series.claimed) & ~shown) | series.claimed_nonfinite
        self.claimed.set_data(t[shown], series.claimed[shown])
        self.above.set_data(t[above], np.full(int(above.sum()), ceiling * 0.985))
        gone = series.not_delivered
        self.gone.set_data(t[gone], np.zeros(int(gone.sum())))
        self.angle.set_data(*_unwrapped_gaps(t, series.angle_expected))
        self.angle_claimed.set_data(t, series.angle_claimed)
        off = series.angle_off
        self.angle_off.set_data(t[off], np.full(int(off.sum()), 3.9))
        self.expected.set_data(t, series.warning_expected)
        self.got.set_data(t, series.warning_got)

        always = {self.nearest, self.threshold, self.claimed, self.angle, self.angle_claimed}
        optional = {self.above: above, self.gone: gone, self.angle_off: off}
        shown_keys = always | {self.expected, self.got}
        shown_keys |= {line for line, mask in optional.items() if mask.any()}
        if series.failed.any():
            shown_keys.add(self.failed_key)
        if band:
            shown_keys.add(self.band_key)
        background = self._background(shown_keys)
        bottom.set_xlim(*((t[0] - step, t[-1] + step) if t.size else _EMPTY_XLIM))
        note = "no ticks" if not t.size else ""
        if t.size and np.isnan(series.nearest).all():
            note = "no valid return in any scan: nothing in range"
        self.note.set_text(note)

        self.layers.prepare(self.canvas)
        self.canvas.restore_region(background)
        renderer = self.canvas.get_renderer()
        for artist in (*self.axes, self.title):  # drawn as Figure.draw orders them
            artist.draw(renderer)
        out = io.BytesIO()
        pixels, unstamped = self.canvas.buffer_rgba(), {"Software": None}
        imsave(out, pixels, format="png", dpi=DPI, metadata=unstamped, pil_kwargs=PNG_FAST)
        return out.getvalue()


def _bars(spans: list[tuple[float, float]]) -> list[list[tuple[float, float]]]:
    """`spans` ((x, width) pairs) as the corners of full-height bars (y in axes units)."""
    return [[(x, 0), (x, 1), (x + w, 1), (x + w, 0)] for x, w in spans]


_EMPTY_XLIM = (-0.055, 0.055)  # what autoscaling gave a run without ticks
_canvas: list[_Canvas] = []  # built by the first plot of the process
_drawing = threading.Lock()  # one figure: one plot at a time


def prepare_canvas() -> None:
    """Import matplotlib and build the process's figure now (a second or so of CPU), for a
    process that has idle time before its first plot (a grading judge at its start)."""
    with _drawing:
        if not _canvas:
            _canvas.append(_Canvas())


def render_plot(series: PlotSeries) -> bytes:
    """The PNG bytes (deterministic: no software or date in the metadata)."""
    prepare_canvas()
    with _drawing:
        return _canvas[0].draw(series)


def write_plot(path: Path, result: RunResult) -> Path:
    """The report's plot writer: render, then write atomically."""
    return write_atomically(path, render_plot(plot_series(result)))
