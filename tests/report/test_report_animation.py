"""The animated top-down view of a run (`--animate`): a GIF, bounded, safe with any status."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib import animation as mpl_animation
from PIL import Image

from harness.cli import main
from harness.errors import ConfigError
from harness.judge.records import RunResult
from harness.lidar.scan import Scan
from harness.links.base import LinkOptions
from harness.report.animation import (
    FAILED_BACKGROUND,
    MAX_FRAMES,
    frame_indices,
    robot_body,
    view_bounds,
    write_animation,
)
from harness.report.outputs import artifact_writers, write_report
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario
from harness.scenario.schema import Model

MAX_BYTES = 2_000_000
HOSTILE = "\x1b[31m$\\foo$ Min distance: {d:.3f} m,\nangle: {a:.3f} rad\x1b[0m $x^{{ \u202e"


def hostile_status(scan: Scan, threshold: float) -> tuple[str, bool | None]:
    """A processing function: the right numbers wrapped in mathtext, a newline, ANSI
    colour and a bidi override; the warning only when it is True (none otherwise)."""
    ranges = scan.ranges.tolist()
    valid = [(r, i) for i, r in enumerate(ranges) if scan.range_min <= r <= scan.range_max]
    if not valid:
        return "no obstacle $", None
    d, i = min(valid)
    a = scan.angle_min + i * scan.angle_increment
    return HOSTILE.format(d=d, a=a), (True if d < threshold else None)


def _frames(path: Path) -> list[Image.Image]:
    with Image.open(path) as gif:
        assert gif.format == "GIF"
        frames = []
        for k in range(gif.n_frames):
            gif.seek(k)
            frames.append(gif.convert("RGB"))
        return frames


def _shaded(frame: Image.Image) -> int:
    """Pixels in the colour that marks a failed tick."""
    rgb = tuple(int(FAILED_BACKGROUND[i : i + 2], 16) for i in (1, 3, 5))
    return int(np.all(np.asarray(frame) == rgb, axis=-1).sum())


@pytest.fixture(scope="module")
def approach_gif(tmp_path_factory: pytest.TempPathFactory, passing: RunResult) -> Path:
    """approach_wall's whole run (95 ticks, one frame each)."""
    path = tmp_path_factory.mktemp("animation") / "approach_wall.gif"
    assert write_animation(passing, resolve_scenario("approach_wall"), path) == path
    return path


@pytest.mark.slow
def test_a_passing_run_is_a_small_gif_with_a_frame_per_tick(
    approach_gif: Path, passing: RunResult
) -> None:
    """Fewer ticks than MAX_FRAMES: every tick a frame, played in simulated time."""
    assert len(passing.records) <= MAX_FRAMES
    frames = _frames(approach_gif)
    assert len(frames) == len(passing.records)
    assert frames[0].size == (480, 448)
    assert approach_gif.stat().st_size < MAX_BYTES
    with Image.open(approach_gif) as gif:
        assert gif.info["duration"] == 100  # the gazebo preset's 10 Hz
        assert gif.info["loop"] == 0
    assert not any(_shaded(f) for f in frames)  # nothing failed, nothing marked
    assert not [p.name for p in approach_gif.parent.iterdir() if p.name.startswith(".")]


def test_the_same_run_gives_the_same_bytes(tmp_path: Path, passing: RunResult) -> None:
    scenario = resolve_scenario("approach_wall")
    one = write_animation(passing, scenario, tmp_path / "one.gif", max_frames=8)
    two = write_animation(passing, scenario, tmp_path / "two.gif", max_frames=8)
    assert one.read_bytes() == two.read_bytes()
    assert len(_frames(one)) == 8


def test_a_long_run_is_subsampled_and_keeps_its_first_failure(
    tmp_path: Path, failing: RunResult
) -> None:
    """Fewer frames than ticks; the first failed tick is among them, marked as failed."""
    limit = 24
    path = write_animation(
        failing, resolve_scenario("drive_past_10m"), tmp_path / "f.gif", max_frames=limit
    )
    frames = _frames(path)
    assert len(frames) == limit < len(failing.records)
    records = sorted(failing.records, key=lambda r: r.t)
    picks = frame_indices(
        len(records), [i for i, r in enumerate(records) if not r.verdict.ok], limit
    )
    assert [bool(_shaded(f)) for f in frames] == [not records[i].verdict.ok for i in picks]
    first = next(i for i, r in enumerate(records) if not r.verdict.ok)
    assert first in picks and _shaded(frames[picks.index(first)]) > 1000
    assert path.stat().st_size < MAX_BYTES


def test_frame_indices_are_bounded_even_and_keep_the_first_failure() -> None:
    assert frame_indices(95) == list(range(95))
    picks = frame_indices(1000)
    assert len(picks) == MAX_FRAMES == len(set(picks))
    assert picks[0] == 0 and picks[-1] == 999 and picks == sorted(picks)
    assert 500 in frame_indices(1000, failed=[500, 501], limit=10)
    assert len(frame_indices(1000, failed=[500], limit=10)) == 10
    assert frame_indices(0) == []


def test_a_hostile_status_is_drawn_as_text(tmp_path: Path) -> None:
    """Mathtext, newlines, ANSI escapes and a bidi override in the status: drawn, not parsed."""
    from matplotlib.mathtext import MathTextParser

    with pytest.raises(ValueError):  # what matplotlib would make of it as mathtext
        MathTextParser("agg").parse("$\\foo$")
    scenario = resolve_scenario("approach_wall")
    processor = f"{Path(__file__)}:hostile_status"
    [result] = run_suite([scenario], "inprocess", LinkOptions(processor=processor))
    statuses = {r.verdict.claim.text for r in result.records if r.verdict.claim is not None}
    assert any("$\\foo$" in s and "\n" in s and "\x1b[31m" in s for s in statuses)
    assert {r.verdict.warning_got for r in result.records} == {True, None}
    path = write_animation(result, scenario, tmp_path / "hostile.gif", max_frames=12)
    assert len(_frames(path)) == 12


def test_models_are_marked_and_the_lidar_sits_where_the_urdf_says(
    tmp_path: Path, passing: RunResult
) -> None:
    scenario = resolve_scenario("approach_wall")
    assert robot_body(scenario).lidar == pytest.approx((-0.016, 0.0, 0.0))
    model = Model(type="model", path="fossbot_v2.urdf", position=(1.0, 1.0, 0.0))
    with_model = scenario.model_copy(update={"obstacles": [*scenario.obstacles, model]})
    path = write_animation(passing, with_model, tmp_path / "model.gif", max_frames=3)
    assert len(_frames(path)) == 3


def test_the_view_leaves_out_what_is_far_from_the_path(passing: RunResult) -> None:
    """out_of_range's wall 20 m away would shrink the robot to a dot."""
    x0, _, x1, _ = view_bounds(resolve_scenario("out_of_range"), [])
    assert x1 < 5 and x0 > -5
    x0, y0, x1, y1 = view_bounds(resolve_scenario("approach_wall"), passing.records)
    assert x1 >= 2.05 and y0 <= -2 and y1 >= 2  # the whole wall


def test_mp4_without_ffmpeg_is_one_line_naming_it(tmp_path: Path, passing: RunResult) -> None:
    with matplotlib.rc_context({"animation.ffmpeg_path": str(tmp_path / "no-ffmpeg-here")}):
        assert not mpl_animation.writers.is_available("ffmpeg")
        with pytest.raises(ConfigError, match="needs ffmpeg") as err:
            write_animation(passing, resolve_scenario("approach_wall"), tmp_path / "run.mp4")
    assert "\n" not in str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_mp4_with_ffmpeg(tmp_path: Path, passing: RunResult) -> None:
    """A real ffmpeg: the static build the imageio-ffmpeg wheel carries (test extra)."""
    import imageio_ffmpeg

    with matplotlib.rc_context({"animation.ffmpeg_path": imageio_ffmpeg.get_ffmpeg_exe()}):
        assert mpl_animation.writers.is_available("ffmpeg")
        path = write_animation(
            passing, resolve_scenario("approach_wall"), tmp_path / "r.mp4", max_frames=4
        )
    data = path.read_bytes()
    assert len(data) > 0 and data[4:8] == b"ftyp"  # an MP4 container


def test_another_suffix_is_refused(tmp_path: Path, passing: RunResult) -> None:
    with pytest.raises(ConfigError, match=r"\.gif"):
        write_animation(passing, resolve_scenario("approach_wall"), tmp_path / "run.webm")
    assert list(tmp_path.iterdir()) == []


def test_the_report_folder_writes_and_links_it(tmp_path: Path, passing: RunResult) -> None:
    """With a scenario, `animation` is a file of the folder; without, it is null."""
    scenario = resolve_scenario("approach_wall")
    short = replace(passing, records=passing.records[::12])
    write_report(tmp_path, [short, short], artifact_writers(animate=True), [scenario, None])
    summary = json.loads((tmp_path / "summary.json").read_text())
    files = [e["files"] for e in summary["scenarios"]]
    assert files[0]["animation"] == "scenarios/approach_wall.gif"
    assert files[1]["animation"] is None and files[1]["plot"] == "scenarios/approach_wall-2.png"
    assert len(_frames(tmp_path / files[0]["animation"])) == len(short.records)
    page = (tmp_path / "index.html").read_text()
    assert '<img src="scenarios/approach_wall.gif"' in page
    assert "approach_wall-2.gif" not in page


@pytest.mark.slow
def test_run_animate_writes_the_gif_beside_the_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "report"
    code = main(["run", "approach_wall", "--link", "inprocess", "--out", str(out), "--animate"])
    captured = capsys.readouterr()
    assert code == 0, captured.out + captured.err
    gif = out / "scenarios" / "approach_wall.gif"
    assert (out / "scenarios" / "approach_wall.png").is_file()
    assert len(_frames(gif)) == 95 and gif.stat().st_size < MAX_BYTES
    assert 'href="scenarios/approach_wall.gif"' in (out / "index.html").read_text()
    [entry] = json.loads((out / "summary.json").read_text())["scenarios"]
    assert entry["files"]["animation"] == "scenarios/approach_wall.gif"


def test_animate_without_out_exits_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["run", "approach_wall", "--link", "inprocess", "--animate"]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1
    assert captured.err.startswith("fossbot-hil: error: --animate needs --out")
    assert captured.out == "" and list(tmp_path.iterdir()) == []


def test_no_ticks_is_one_frame_of_the_world(tmp_path: Path) -> None:
    empty = RunResult("approach_wall", "inprocess", 0, 0.5, "clean")
    path = write_animation(empty, resolve_scenario("approach_wall"), tmp_path / "none.gif")
    assert len(_frames(path)) == 1
