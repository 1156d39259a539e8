"""An animated top-down view of one scenario run (GIF): evidence that a node works.

Students used to hand in screen recordings of Gazebo, which show the world
but not what the node said. Each frame shows the world, the robot, the scan
the node saw, where its status puts the nearest obstacle, and below the map
its status, warning lamp, what a correct node says and the tick's verdict.
Bounded, so `run --animate` stays cheap: at most `MAX_FRAMES` frames (the
first failed tick always among them), played in simulated time. The same
run gives the same bytes; matplotlib is imported only when drawing.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from harness.atomic_write import fill_atomically
from harness.errors import ConfigError
from harness.judge.records import RunResult, TickRecord
from harness.judge.verdicts import verdict_of
from harness.report.plot import draw_text
from harness.safe_text import clip, shown, visible
from harness.scenario.footprint import Outline, disc, robot_outlines
from harness.scenario.model_files import find_model_file, parse_xml, robot_models_dir
from harness.scenario.schema import Model, Scenario
from harness.scenario.urdf_chain import chain_to_root, joint_origin, joints_by_child

if TYPE_CHECKING:
    from matplotlib.animation import AbstractMovieWriter
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["MAX_FRAMES", "RobotBody", "frame_indices", "robot_body", "write_animation"]

MAX_FRAMES = 150  # a longer run is subsampled to this many frames
WIDTH_IN, HEIGHT_IN, DPI = 6.0, 5.6, 80  # 480 x 448 px (even: an .mp4 needs that)
MAP = (0.09, 0.33, 0.88, 0.57)  # the map's place in the figure: left, bottom, width, height
MIN_FPS, MAX_FPS = 4.0, 20.0  # simulated time, unless that is slower or faster than these
AROUND_PATH = 1.0  # m of floor shown around the robot's path
REACH = 4.0  # m: obstacles (or their parts) farther from the path are left out of view
STATUS_CHARS, FAILURE_CHARS = 60, 86  # characters shown (the status leaves room for the lamp)
FALLBACK_RADIUS = 0.1  # m: the robot as a disc when its URDF cannot be read

OBSTACLE, OBSTACLE_EDGE = "#9a9a9a", "#555555"
ROBOT, ROBOT_EDGE = "#cfe0f5", "#1f5fa8"
TRAIL, RETURN, INVALID, NEAREST = "#8fb3e0", "#5b8fd1", "#c4c4c4", "#0b3d91"
CLAIM = "#e07b00"
PASS, FAIL, FAILED_BACKGROUND = "#1a7f37", "#c62828", "#fbe3e3"
LAMP_ON, LAMP_OFF, LAMP_NONE = "#d62728", "#9e9e9e", "#ffffff"
LEGEND = {"loc": "upper center", "bbox_to_anchor": (0.5, 0.955), "ncols": 6, "fontsize": 6}
LEGEND |= {"frameon": False, "handletextpad": 0.3, "columnspacing": 1.0, "markerscale": 1.5}


@dataclass(frozen=True)
class RobotBody:
    """The robot seen from above, in its base frame, and where its LIDAR's scan frame is."""

    parts: tuple[Outline, ...]
    lidar: tuple[float, float, float]  # x, y, yaw of the scan frame in the base frame


def frame_indices(count: int, failed: Sequence[int] = (), limit: int = MAX_FRAMES) -> list[int]:
    """Which of `count` ticks (in time order) become frames: every one up to `limit`,
    else `limit` evenly spaced, the first of the `failed` ticks always among them."""
    if count <= limit:
        return list(range(count))
    picks = np.linspace(0, count - 1, limit).round().astype(int).tolist()
    if failed and failed[0] not in picks:
        nearest = min(range(limit), key=lambda i: abs(picks[i] - failed[0]))
        picks[nearest] = failed[0]
    return sorted(picks)


def _mount(root: ET.Element, link: str) -> tuple[float, float, float]:
    """Where `link` sits in the URDF's root frame, seen from above (x, y, yaw): roll and
    pitch left out, as a scanning LIDAR stands upright; moving joints at zero."""
    joints = joints_by_child(root)
    x = y = yaw = 0.0
    for child in chain_to_root(joints, link)[:-1]:
        (ox, oy, _), (_, _, oyaw) = joint_origin(joints[child])
        c, s = math.cos(oyaw), math.sin(oyaw)
        x, y, yaw = ox + c * x - s * y, oy + s * x + c * y, oyaw + yaw
    return x, y, yaw


def robot_body(scenario: Scenario) -> RobotBody:
    """The scenario's robot from its URDF (checked when the scenario was loaded), so the
    returns start at the LIDAR, not the base; a disc with the LIDAR at its centre
    when the file cannot be read (a scenario built in code)."""
    what = f"robot.urdf {scenario.robot.urdf!r}"
    try:
        folders = [scenario.base_dir, robot_models_dir()]
        root = parse_xml(find_model_file(scenario.robot.urdf, folders, what=what).path, what)
        parts = tuple(robot_outlines(root))
        mount = _mount(root, scenario.robot.lidar_link)
    except (ConfigError, OSError, ValueError):
        return RobotBody((disc((0.0, 0.0), FALLBACK_RADIUS, 0.1),), (0.0, 0.0, 0.0))
    return RobotBody(parts or (disc((0.0, 0.0), FALLBACK_RADIUS, 0.1),), mount)


def _footprint(obstacle: Any) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max) of an obstacle seen from above (a model: its origin)."""
    if isinstance(obstacle, Model):
        x, y, _ = obstacle.position
        return x, y, x, y
    return obstacle.outline().bounds()


def view_bounds(scenario: Scenario, records: Sequence[TickRecord]) -> tuple[float, ...]:
    """The floor shown: the path with a metre around it, and the obstacles near it (a
    wall 20 m away, out of the LIDAR's range, would shrink everything else to dots)."""
    xs = [r.x for r in records] or [scenario.robot.start.x]
    ys = [r.y for r in records] or [scenario.robot.start.y]
    near = (min(xs) - REACH, min(ys) - REACH, max(xs) + REACH, max(ys) + REACH)
    x0, y0 = min(xs) - AROUND_PATH, min(ys) - AROUND_PATH
    x1, y1 = max(xs) + AROUND_PATH, max(ys) + AROUND_PATH
    for obstacle in scenario.obstacles:
        bx0, by0, bx1, by1 = _footprint(obstacle)
        bx0, by0 = max(bx0, near[0]), max(by0, near[1])
        bx1, by1 = min(bx1, near[2]), min(by1, near[3])
        if bx0 <= bx1 and by0 <= by1:
            x0, y0, x1, y1 = min(x0, bx0), min(y0, by0), max(x1, bx1), max(y1, by1)
    return x0, y0, x1, y1


def _fitted(bounds: Sequence[float], width: float, height: float) -> tuple[float, ...]:
    """`bounds` widened (about their centre) to the shape of a `width` x `height` box,
    so a metre is as long across as up."""
    x0, y0, x1, y1 = bounds
    span_x, span_y = max(x1 - x0, 1e-3), max(y1 - y0, 1e-3)
    if span_x / span_y < width / height:
        grow = (span_y * width / height - span_x) / 2
        return x0 - grow, y0, x1 + grow, y1
    grow = (span_x * height / width - span_y) / 2
    return x0, y0 - grow, x1, y1 + grow


def _one_line(text: str, limit: int) -> str:
    """Text from the node as one line of at most `limit` characters, newlines escaped too."""
    text = visible(clip(text, 4 * limit)).replace("\n", "\\n").replace("\t", "\\t")
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _number(x: float | None, unit: str = "") -> str:
    return "none" if x is None else f"{x:.3f}{unit}" if math.isfinite(x) else str(x)


def _expected_text(record: TickRecord) -> str:
    exp = record.verdict.expected
    warning = {True: "True", False: "False", None: "either"}[exp.warning]
    if not exp.obstacle:
        return f"expected: no valid return · warning {warning}"
    angle = _number(exp.angle, " rad")
    return f"expected: nearest {_number(exp.distance, ' m')} at {angle} · warning {warning}"


def _outline_patch(outline: Outline, **style: Any) -> Any:
    """A matplotlib patch for an outline (its rounding left out, except a disc's)."""
    from matplotlib.patches import Circle, Polygon

    if len(outline.points) == 1:
        return Circle(outline.points[0], max(outline.radius, 0.005), **style)
    return Polygon(outline.points, closed=True, **style)


def _place(patch: Any, outline: Outline) -> None:
    if len(outline.points) == 1:
        patch.set_center(outline.points[0])
    else:
        patch.set_xy(outline.points)


def _draw_world(ax: Axes, scenario: Scenario) -> None:
    """Walls, boxes and cylinders as filled shapes; models as a labelled diamond."""
    for obstacle in scenario.obstacles:
        if isinstance(obstacle, Model):
            x, y, _ = obstacle.position
            ax.plot([x], [y], "D", ms=5, color=OBSTACLE_EDGE)
            name = f" model {Path(obstacle.path).name} (shape not drawn)"
            draw_text(ax, x, y, shown(name, 60), fontsize=6, va="center", clip_on=True)
            continue
        patch = _outline_patch(obstacle.outline(), facecolor=OBSTACLE, edgecolor=OBSTACLE_EDGE)
        ax.add_patch(patch)


class _View:
    """The figure and the artists that change from frame to frame; with `blit` the rest is
    drawn once and each frame only what changed over a copy (ten times faster; an .mp4's
    writer redraws it all)."""

    def __init__(
        self, result: RunResult, scenario: Scenario, records: Sequence[TickRecord], blit: bool
    ) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.fig: Figure = Figure(figsize=(WIDTH_IN, HEIGHT_IN), dpi=DPI)
        self.canvas = FigureCanvasAgg(self.fig)
        self.blit = blit
        self.changing: list[Any] = []  # in drawing order
        self.body = robot_body(scenario)
        corners = [math.hypot(*p) + o.radius for o in self.body.parts for p in o.points]
        self.reach = max(0.12, *corners)  # m: the heading line ends just past the body
        self.path = np.array([(r.x, r.y) for r in records], dtype=float).reshape(-1, 2)
        self.ax = self.fig.add_axes(MAP)
        self._panel_background()
        self._map(scenario, records, float(result.threshold))
        self._panel(result)
        self.background = None
        if blit:
            self.canvas.draw()
            self.background = self.canvas.copy_from_bbox(self.fig.bbox)

    def _changes(self, artist: Any) -> Any:
        """`artist` is drawn anew in every frame."""
        artist.set_animated(self.blit)
        self.changing.append(artist)
        return artist

    def _line(self, *style: Any, **more: Any) -> Any:
        (line,) = self.ax.plot([], [], *style, **more)
        return self._changes(line)

    def _panel_background(self) -> None:
        from matplotlib.patches import Rectangle

        shade = Rectangle((0, 0), 1, 0.25, transform=self.fig.transFigure, color=FAILED_BACKGROUND)
        self.shade = self._changes(self.fig.add_artist(shade))

    def _map(self, scenario: Scenario, records: Sequence[TickRecord], threshold: float) -> None:
        from matplotlib.patches import Circle

        ax = self.ax
        x0, y0, x1, y1 = _fitted(
            view_bounds(scenario, records), MAP[2] * WIDTH_IN, MAP[3] * HEIGHT_IN
        )
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal", adjustable="box")  # the limits fit the box: nothing moves
        ax.tick_params(labelsize=7)
        ax.set_xlabel("x, m", fontsize=7, labelpad=1)
        ax.set_ylabel("y, m", fontsize=7, labelpad=1)
        ax.grid(True, lw=0.3, alpha=0.5)
        _draw_world(ax, scenario)
        ax.plot(self.path[:, 0], self.path[:, 1], ":", lw=0.8, color="#aaaaaa")
        self.trail = self._line("-", lw=1.2, color=TRAIL, label="path")
        self.robot = [
            self._changes(ax.add_patch(_outline_patch(p, fc=ROBOT, ec=ROBOT_EDGE, lw=0.8)))
            for p in self.body.parts
        ]
        self.heading = self._line("-", lw=1.5, color=ROBOT_EDGE)
        zone = Circle((0, 0), threshold, fill=False, ls="--", lw=0.7, color="#777777")
        self.zone = self._changes(ax.add_patch(zone))
        self.invalid = self._line(".", ms=2, color=INVALID, label="invalid return")
        self.returns = self._line(".", ms=2.5, color=RETURN, label="valid return")
        self.ray = self._line("-", lw=0.8, color=NEAREST)
        self.nearest = self._line("o", ms=5, color=NEAREST, label="nearest")
        self.claim = self._line("x", ms=7, mew=1.6, color=CLAIM, label="node's nearest")
        ax.plot([], [], "--", lw=0.7, color="#777777", label="threshold")
        self.fig.legend(**LEGEND)

    def _text(self, x: float, y: float, **style: Any) -> Any:
        return self._changes(draw_text(self.fig, x, y, "", **style))

    def _panel(self, result: RunResult) -> None:
        from matplotlib.lines import Line2D

        fig = self.fig
        title = f"{result.scenario} · {result.link} · {verdict_of(result)}"
        draw_text(fig, 0.5, 0.99, shown(title, 90), fontsize=9, ha="center", va="top")
        self.clock = self._text(0.02, 0.205, fontsize=8, weight="bold")
        self.verdict = self._text(0.98, 0.205, fontsize=9, weight="bold", ha="right")
        self.status = self._text(0.02, 0.145, fontsize=8)
        self.expected = self._text(0.02, 0.085, fontsize=8, color="#444444")
        self.failure = self._text(0.02, 0.025, fontsize=8, color=FAIL)
        lamp = Line2D([0.93], [0.14], marker="o", ms=15, mew=1.5, ls="", transform=fig.transFigure)
        self.lamp = self._changes(fig.add_artist(lamp))
        self.lamp_label = self._text(0.93, 0.075, fontsize=7, ha="center")

    def show(self, record: TickRecord, index: int, note: str = "") -> None:
        """Draw tick `record`, the `index`-th of the run in time order."""
        self._robot(record, index)
        self._scan(record)
        self._words(record, note)
        if self.background is not None:
            self.canvas.restore_region(self.background)
            for artist in self.changing:
                self.fig.draw_artist(artist)

    def _lidar_pose(self, record: TickRecord) -> tuple[float, float, float]:
        mx, my, myaw = self.body.lidar
        c, s = math.cos(record.yaw), math.sin(record.yaw)
        return record.x + c * mx - s * my, record.y + s * mx + c * my, record.yaw + myaw

    def _robot(self, record: TickRecord, index: int) -> None:
        for patch, part in zip(self.robot, self.body.parts, strict=True):
            _place(patch, part.placed(record.x, record.y, record.yaw))
        c, s = math.cos(record.yaw), math.sin(record.yaw)
        tip = (record.x + self.reach * c, record.y + self.reach * s)
        self.heading.set_data([record.x, tip[0]], [record.y, tip[1]])
        self.trail.set_data(self.path[: index + 1, 0], self.path[: index + 1, 1])

    def _scan(self, record: TickRecord) -> None:
        """The scan the node saw (a board driver's, over a serial link), as it says it."""
        seen = record.answers.seen if record.answers.seen is not None else record.scan
        lx, ly, lyaw = self._lidar_pose(record)
        self.zone.set_center((lx, ly))
        ranges = seen.ranges.astype(float)
        heading = lyaw + seen.angles()
        with np.errstate(invalid="ignore"):
            px, py = lx + ranges * np.cos(heading), ly + ranges * np.sin(heading)
        valid, finite = seen.valid_mask(), np.isfinite(ranges)
        self.returns.set_data(px[valid], py[valid])
        self.invalid.set_data(px[finite & ~valid], py[finite & ~valid])
        index = record.verdict.expected.index
        near = [] if index is None else [index]
        self.nearest.set_data(px[near], py[near])
        self.ray.set_data([lx, *px[near]] if near else [], [ly, *py[near]] if near else [])
        self.claim.set_data(*_claimed_point(record, lx, ly, lyaw))

    def _words(self, record: TickRecord, note: str) -> None:
        v = record.verdict
        self.shade.set_visible(not v.ok)
        self.clock.set_text(f"t = {record.t:.2f} s   tick {record.tick}{note}")
        self.verdict.set_text("PASS" if v.ok else "FAIL")
        self.verdict.set_color(PASS if v.ok else FAIL)
        status = "none arrived" if v.claim is None else f"'{_one_line(v.claim.text, STATUS_CHARS)}'"
        self.status.set_text(f"status: {status}")
        self.expected.set_text(_expected_text(record))
        self.failure.set_text(
            "" if v.ok or not v.failures else _one_line(v.failures[0], FAILURE_CHARS)
        )
        got = v.warning_got
        self.lamp.set_markerfacecolor({True: LAMP_ON, False: LAMP_OFF, None: LAMP_NONE}[got])
        self.lamp.set_markeredgecolor(LAMP_OFF if got is None else "#333333")
        self.lamp_label.set_text(f"warning: {'none' if got is None else got}")

    def empty(self) -> None:
        """The world alone, for a run without ticks."""
        draw_text(self.ax, 0.5, 0.5, "no ticks", transform=self.ax.transAxes, ha="center")
        self.shade.set_visible(False)
        self.canvas.draw()


def _claimed_point(record: TickRecord, lx: float, ly: float, lyaw: float) -> tuple[list, list]:
    """Where the node's status puts the nearest obstacle (nothing when it gives no
    finite distance and angle), in the scan's own angles."""
    claim = record.verdict.claim
    if claim is None or not claim.obstacle or claim.distance is None or claim.angle is None:
        return [], []
    d, a = claim.distance, claim.angle
    if not (math.isfinite(d) and math.isfinite(a)):
        return [], []
    return [lx + d * math.cos(lyaw + a)], [ly + d * math.sin(lyaw + a)]


def _palette() -> list[int]:
    """One fixed GIF palette: the colours drawn, a grey ramp (text, anti-aliasing) and a
    colour cube. Every frame maps to it: fast, deterministic, and frames differ only
    where the picture changed, which keeps the file small."""
    named = [ROBOT, ROBOT_EDGE, TRAIL, RETURN, NEAREST, CLAIM, PASS, FAIL, FAILED_BACKGROUND]
    colours = [tuple(int(c[i : i + 2], 16) for i in (1, 3, 5)) for c in [*named, LAMP_ON]]
    colours += [(v, v, v) for v in np.linspace(0, 255, 30).round().astype(int).tolist()]
    cube = (0, 51, 102, 153, 204, 255)
    colours += [(r, g, b) for r in cube for g in cube for b in cube]
    return [channel for colour in colours[:256] for channel in colour]


def _gif_writer(fps: float) -> AbstractMovieWriter:
    """matplotlib's PillowWriter, taking each frame from the canvas as drawn (blitted)
    instead of redrawing the figure, and mapping it to one palette as it comes."""
    from matplotlib.animation import PillowWriter
    from PIL import Image

    class CanvasPillowWriter(PillowWriter):
        def setup(self, fig: Figure, outfile: Any, dpi: float | None = None) -> None:
            super().setup(fig, outfile, dpi=dpi)
            self.palette = Image.new("P", (1, 1))
            self.palette.putpalette(_palette())
            self.images: list[Any] = []

        def grab_frame(self, **_: Any) -> None:
            rgba = self.fig.canvas.buffer_rgba()
            frame = Image.frombuffer("RGBA", self.frame_size, rgba, "raw", "RGBA", 0, 1)
            rgb = frame.convert("RGB")
            self.images.append(rgb.quantize(palette=self.palette, dither=Image.Dither.NONE))

        def finish(self) -> None:
            first, *rest = self.images
            duration = round(1000 / self.fps)
            first.save(self.outfile, save_all=True, append_images=rest, duration=duration, loop=0)

    return CanvasPillowWriter(fps=fps)


def _fps(records: Sequence[TickRecord]) -> float:
    """Frames a second that play the frames in simulated time, within MIN_FPS..MAX_FPS."""
    if len(records) < 2 or records[-1].t <= records[0].t:
        return MIN_FPS
    per_frame = (records[-1].t - records[0].t) / (len(records) - 1)
    return min(MAX_FPS, max(MIN_FPS, 1.0 / per_frame))


def _movie_writer(path: Path, fps: float) -> AbstractMovieWriter:
    """PillowWriter for a .gif; ffmpeg for an .mp4, when matplotlib finds it."""
    from matplotlib import animation

    suffix = path.suffix.lower()
    if suffix == ".gif":
        return _gif_writer(fps)
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ConfigError(
                f"{shown(str(path))}: an .mp4 animation needs ffmpeg, which matplotlib does not "
                "find (install ffmpeg, or write a .gif)"
            )
        return animation.FFMpegWriter(fps=fps)
    raise ConfigError(
        f"{shown(str(path))}: an animation is written as .gif (or .mp4 with ffmpeg), "
        f"not {shown(suffix) or 'a file without a suffix'}"
    )


def _render(result: RunResult, scenario: Scenario, path: Path, limit: int) -> None:
    records = sorted(result.records, key=lambda r: r.t)  # a reordered scan was judged late
    failed = [i for i, r in enumerate(records) if not r.verdict.ok]
    picks = frame_indices(len(records), failed, limit)
    writer = _movie_writer(path, _fps([records[i] for i in picks]))
    view = _View(result, scenario, records, blit=path.suffix.lower() == ".gif")
    note = f"   ({len(picks)} of {len(records)} ticks shown)" if len(picks) < len(records) else ""
    with writer.saving(view.fig, str(path), DPI):
        for index in picks:
            view.show(records[index], index, note)
            writer.grab_frame()
        if not picks:
            view.empty()
            writer.grab_frame()


def write_animation(
    result: RunResult, scenario: Scenario, path: str | Path, *, max_frames: int = MAX_FRAMES
) -> Path:
    """Write the animated top-down view of `result`, a run of `scenario`, to `path`
    atomically: `.gif`, or `.mp4` where matplotlib finds ffmpeg (else a ConfigError)."""
    target = Path(path)
    _movie_writer(target, MIN_FPS)  # a bad suffix fails before anything is drawn
    limit = max(1, max_frames)

    def fill(temporary: Path) -> Path:
        _render(result, scenario, temporary, limit)
        return temporary

    return fill_atomically(target, fill, suffix=target.suffix)
