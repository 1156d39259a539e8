"""Each axes' ticks, tick labels, grid and axis label, drawn once per set of limits.

Drawing the axes' decorations is two thirds of a plot's time (the tick labels'
text above all), and they are the same picture whenever the limits are: a class
graded on one scenario draws every student's plot on the same axes. So each
axes' decorations are drawn alone, onto a transparent canvas, once per set of
limits, and pasted back where matplotlib draws them (between the failed-tick
bars and the lines), every time, the first time too: a PNG still depends on its
series only.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np
from matplotlib.artist import Artist

__all__ = ["AxisLayers"]

KEPT = 16  # sets of limits kept (about 2 MB each): a class's scenarios
MARGIN_PX = 12  # above an axes: its tick marks and the top tick label's upper half
BELOW_PX = 56  # below an axes: the x tick labels and the axis label under them
ZORDER = 1.5  # where matplotlib draws an axis when ``axes.axisbelow`` is "line"


class _Layer(Artist):
    """One axes' decorations as pixels, drawn at the axis's place among the axes' artists."""

    zorder = ZORDER

    def __init__(self) -> None:
        super().__init__()
        self.set_clip_on(False)
        self.set_in_layout(False)
        self.pixels: np.ndarray | None = None
        self.at = (0, 0)  # its lower left corner, in figure pixels

    def draw(self, renderer: Any) -> None:
        if self.pixels is None or not self.get_visible():
            return
        gc = renderer.new_gc()
        renderer.draw_image(gc, *self.at, self.pixels)
        gc.restore()


class AxisLayers:
    """`axes`' decorations as layers: `prepare` before each draw of the figure."""

    def __init__(self, axes: tuple[Any, ...]) -> None:
        self.axes = axes
        self.layers = [_Layer() for _ in axes]
        for ax, layer in zip(axes, self.layers, strict=True):
            ax.add_artist(layer)
        self._drawn: OrderedDict[tuple[Any, ...], list[tuple[np.ndarray, tuple[int, int]]]]
        self._drawn = OrderedDict()

    def prepare(self, canvas: Any) -> None:
        """The layers of the axes' limits as they are now (drawn if new; this leaves the
        canvas's pixels undefined: restore the figure's background after)."""
        key = tuple((ax.get_xlim(), ax.get_ylim()) for ax in self.axes)
        if key not in self._drawn:
            self._drawn[key] = self._draw(canvas)
            while len(self._drawn) > KEPT:
                self._drawn.popitem(last=False)
        self._drawn.move_to_end(key)
        for layer, (pixels, at) in zip(self.layers, self._drawn[key], strict=True):
            layer.pixels, layer.at = pixels, at

    def _draw(self, canvas: Any) -> list[tuple[np.ndarray, tuple[int, int]]]:
        renderer = canvas.get_renderer()
        width, height = int(renderer.width), int(renderer.height)
        drawn = []
        for ax in self.axes:
            renderer.clear()  # transparent: only the decorations get alpha
            for part in (ax.xaxis, ax.yaxis):
                part.set_visible(True)
                part.draw(renderer)
                part.set_visible(False)  # from now on the layer stands in for it
            # The figure's width (the tick labels on the left) and the axes' height, with
            # room below for the x tick labels and the axis label: measuring each text's
            # extent instead cost as much as drawing it.
            box = ax.bbox
            y0, y1 = max(0, int(box.y0) - BELOW_PX), min(height, int(box.y1) + MARGIN_PX)
            rows = np.asarray(renderer.buffer_rgba())[height - y1 : height - y0, :width]
            pixels = np.ascontiguousarray(rows[::-1])  # draw_image counts rows from the bottom
            drawn.append((pixels, (0, y0)))
        return drawn
