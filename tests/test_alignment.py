"""The board's /scan against the truth: the fitted turn and mirror, and the fix it names.

The board scans are made the way the real chain makes them: the harness
sends scan angle phi at the device angle its mount gives
(``harness.devices.revolution.device_angle_deg``, on the RPLIDAR's
1/64-degree steps, ranges in 1/4 mm), and the bundled driver's pure binning
(``harness.board_driver.binning.rplidar_ranges``, the v2 bridge's floor
binning) turns them into 360 bins over [0, 2 pi), +inf where empty.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from harness.board_driver.binning import rplidar_ranges, scan_increment
from harness.devices.revolution import device_angle_deg
from harness.judge.alignment import Alignment, fit_alignment, likely_fix, run_alignment
from harness.judge.answers import Answers
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.mount import FORWARD, LidarMount, parse_mount
from harness.lidar.scan import Scan

V2 = LidarMount(yaw_deg=-90.0)  # the FOSSBot v2's A1: zero to the right, clockwise
RANGE_MIN, RANGE_MAX = 0.15, 12.0
Segment = tuple[float, float, float, float]
Circle = tuple[float, float, float]


# --- the truth: small 2-D scenes, ray cast -----------------------------------------


def _cast(angles: np.ndarray, segments: list[Segment], circles: list[Circle]) -> np.ndarray:
    """Ranges from the origin along `angles` to the nearest segment or circle (inf: none)."""
    dx, dy = np.cos(angles), np.sin(angles)
    best = np.full(angles.shape, np.inf)
    for x1, y1, x2, y2 in segments:
        ex, ey = x2 - x1, y2 - y1
        den = dx * ey - dy * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (x1 * ey - y1 * ex) / den
            u = (x1 * dy - y1 * dx) / den
        hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
        best = np.where(hit & (t < best), t, best)
    for cx, cy, r in circles:
        b = dx * cx + dy * cy
        c = cx * cx + cy * cy - r * r
        disc = b * b - c
        with np.errstate(invalid="ignore"):
            root = np.sqrt(disc)
        near = np.where(b - root > 0, b - root, b + root)  # inside a circle: the far side
        hit = (disc >= 0) & (near > 0)
        best = np.where(hit & (near < best), near, best)
    return best


def _layout(name: str) -> tuple[float, float]:
    """(angle_min, angle_increment) of the truth's layouts."""
    return {
        "360 -pi..pi": (-math.pi, 2 * math.pi / 360),
        "360 0..2pi": (0.0, 2 * math.pi / 360),
        "720 -pi..pi": (-math.pi, 2 * math.pi / 720),
    }[name]


def _truth(segments: list[Segment], circles: list[Circle], layout: str = "360 -pi..pi") -> Scan:
    angle_min, inc = _layout(layout)
    n = round(2 * math.pi / inc)
    angles = angle_min + np.arange(n) * inc
    ranges = _cast(angles, segments, circles)
    ranges = np.where(ranges <= RANGE_MAX, ranges, np.inf)
    angle_max = angle_min + (n - 1) * inc
    return Scan(angle_min, angle_max, inc, 0.0, 0.1, RANGE_MIN, RANGE_MAX, ranges)


def _corner(dx: float = 0.0, dy: float = 0.0) -> tuple[list[Segment], list[Circle]]:
    """An L corner ahead-left, a wall ahead, a post at the side; the robot moved by (dx, dy)."""
    segments = [
        (1.2 - dx, -2.0 - dy, 1.2 - dx, 0.8 - dy),  # the wall ahead
        (-2.0 - dx, 0.8 - dy, 1.2 - dx, 0.8 - dy),  # the wall on the left, meeting it
    ]
    circles = [(-0.4 - dx, -0.9 - dy, 0.1)]  # a post behind, to the right
    return segments, circles


def _run_scenes(ticks: int = 12, layout: str = "360 -pi..pi") -> list[Scan]:
    """The robot driving towards the corner: one truth scan per tick."""
    return [_truth(*_corner(dx=0.04 * k, dy=0.01 * k), layout=layout) for k in range(ticks)]


# --- the board: the harness's device emulation, then the board's driver -------------


def _board(
    truth: Scan,
    *,
    mount: LidarMount = V2,
    invert: bool = True,
    offset: float = -90.0,
    noise: float = 0.0,
    dropouts: float = 0.0,
    rng: np.random.Generator | None = None,
    mode: str = "floor",
) -> Scan:
    """What the board publishes for `truth`: sent at the mount's device angles, binned
    by the bundled driver with (`invert`, `offset`), the v2 bridge's floor binning
    unless `mode` says, +inf empty."""
    device = np.asarray(device_angle_deg(truth.angles(), mount), dtype=np.float64)
    device = np.floor(device * 64.0) / 64.0  # the A1's angle field: 1/64 degree
    ranges = truth.ranges.astype(np.float64)
    rng = rng if rng is not None else np.random.default_rng(7)
    if noise:
        ranges = ranges + rng.normal(0.0, noise, ranges.shape)
    distances = np.where(np.isfinite(ranges), np.round(ranges * 4000.0) / 4.0, 0.0)
    if dropouts:
        distances[rng.random(distances.shape) < dropouts] = 0.0
    bins = 360
    binned = rplidar_ranges(
        device,
        distances,
        bins,
        range_min=RANGE_MIN,
        range_max=RANGE_MAX,
        invert=invert,
        angle_offset_deg=offset,
        mode=mode,
    )
    inc = scan_increment(bins)
    return Scan(0.0, 2 * math.pi - inc, inc, 0.0, 0.1, RANGE_MIN, RANGE_MAX, binned)


def _fit(truths: list[Scan], mount: LidarMount = V2, **driver: object) -> Alignment:
    fitted = fit_alignment([(t, _board(t, mount=mount, **driver)) for t in truths], mount=mount)  # type: ignore[arg-type]
    assert fitted is not None
    return fitted


def _expected(mount: LidarMount, invert: bool, offset: float) -> tuple[float, bool]:
    """(rotation, mirrored) a driver with (invert, offset) shows for a device on `mount`."""
    mirrored = invert == mount.mirrored
    rotation = offset + mount.yaw_deg if mirrored else offset - mount.yaw_deg
    return 180.0 - ((180.0 - rotation) % 360.0) + 0.0, mirrored  # in (-180, 180]


def _same_turn(a: float, b: float, within: float = 1.0) -> bool:
    return abs((a - b + 180.0) % 360.0 - 180.0) <= within


# --- the fit -----------------------------------------------------------------------


@pytest.mark.parametrize("mode", ["floor", "nearest"])
@pytest.mark.parametrize("layout", ["360 -pi..pi", "360 0..2pi", "720 -pi..pi"])
def test_a_right_driver_is_aligned(layout: str, mode: str) -> None:
    """The v2 bridge's own settings (invert, -90) on the v2 mount: aligned, in every layout,
    binned as the bridge does (floor) or as the bundled driver does by default (nearest)."""
    fitted = _fit(_run_scenes(layout=layout), mode=mode)
    assert fitted.status == "aligned", fitted
    assert fitted.rotation_deg == 0.0 and not fitted.mirrored
    assert fitted.agreement > 0.8 and fitted.identity_agreement > 0.8
    assert fitted.fix == "" and fitted.ticks == 12
    assert "matches the robot's view" in fitted.text()


@pytest.mark.parametrize("mode", ["floor", "nearest"])
@pytest.mark.parametrize("rotation", [90.0, -90.0, 180.0, 37.0, -143.0])
@pytest.mark.parametrize("layout", ["360 -pi..pi", "360 0..2pi", "720 -pi..pi"])
def test_a_turned_board_is_found(rotation: float, layout: str, mode: str) -> None:
    """An angle_offset_deg off by R shows the view turned by R: found to the degree
    (floor binning shows a beam up to a bin early), a round R exactly."""
    fitted = _fit(_run_scenes(layout=layout), offset=-90.0 + rotation, mode=mode)
    assert fitted.status == "misaligned", fitted
    assert not fitted.mirrored and _same_turn(fitted.rotation_deg, rotation)
    if rotation % 5 == 0:
        assert fitted.rotation_deg == rotation
    assert fitted.agreement > 0.8 and fitted.identity_agreement < 0.3
    assert -180.0 < fitted.rotation_deg <= 180.0


@pytest.mark.parametrize("offset", [-90.0, 0.0, 90.0, 53.0])
def test_a_mirrored_board_is_found(offset: float) -> None:
    """invert the wrong way round: the view mirrored, turned by offset + yaw."""
    fitted = _fit(_run_scenes(), invert=False, offset=offset)
    rotation, mirrored = _expected(V2, False, offset)
    assert mirrored and fitted.status == "misaligned", fitted
    assert fitted.mirrored and _same_turn(fitted.rotation_deg, rotation)
    if rotation % 5 == 0:
        assert fitted.rotation_deg == rotation
    assert "flip the board driver's invert" in fitted.fix


def test_the_wall_straight_ahead_shows_at_plus_90_with_offset_0() -> None:
    """The issue's example: the v2 bridge with angle_offset_deg 0 instead of -90."""
    wall = [(1.0, -3.0, 1.0, 1.0)]
    truths = [_truth(wall, [(0.2, 0.9, 0.1)])]
    fitted = _fit(truths, offset=0.0)
    assert (fitted.status, fitted.rotation_deg, fitted.mirrored) == ("misaligned", 90.0, False)
    assert fitted.fix == (
        "the board's /scan is the robot's view turned by +90 deg: set the board driver's "
        "angle_offset_deg 90 deg lower (to -90 for the harness's mount: zero at -90 deg "
        "(to the right), clockwise), or if the board is right, run with --lidar-mount 0"
    )


def test_noise_and_dropouts_keep_the_fit() -> None:
    """2 cm of noise and a fifth of the returns lost: still the same answer."""
    rng = np.random.default_rng(3)
    truths = _run_scenes(ticks=20)
    for offset, status in ((-90.0, "aligned"), (0.0, "misaligned")):
        fitted = _fit(truths, offset=offset, noise=0.02, dropouts=0.2, rng=rng)
        assert fitted.status == status, fitted
        assert _same_turn(fitted.rotation_deg, offset + 90.0)


def test_nothing_in_range_cannot_tell() -> None:
    """All +inf on both sides: unknown, and why."""
    empty = _truth([], [])
    fitted = _fit([empty] * 5)
    assert fitted.status == "unknown" and fitted.fix == ""
    assert fitted.text().startswith("cannot tell: too little in range")


def test_a_round_room_cannot_tell() -> None:
    """The robot in the middle of a round room looks the same turned any way: unknown."""
    room = [_truth([], [(0.0, 0.0, 2.0)]) for _ in range(5)]
    fitted = _fit(room, offset=0.0)
    assert fitted.status == "unknown", fitted
    assert "look alike" in fitted.reason and fitted.fix == ""


def test_a_board_showing_something_else_cannot_tell() -> None:
    """A board whose scans match the truth in no turn: unknown, not a made-up fix."""
    truths = _run_scenes(ticks=6)
    rng = np.random.default_rng(5)
    pairs = []
    for t in truths:
        board = _board(t)
        shuffled = replace(board, ranges=rng.permutation(board.ranges) * 1.7)
        pairs.append((t, shuffled))
    fitted = fit_alignment(pairs, mount=V2)
    assert fitted is not None and fitted.status == "unknown", fitted
    assert "in no turn" in fitted.reason


def test_no_pairs_is_none() -> None:
    """Nothing to compare: no verdict at all."""
    assert fit_alignment([]) is None


# --- the fix, applied, aligns the board ---------------------------------------------

MOUNTS = [V2, FORWARD, LidarMount(180.0, True), LidarMount(30.0, False)]
DRIVERS = [(True, 0.0), (True, -90.0), (False, -90.0), (False, 20.0), (True, 127.0)]


def _lidar_mount_of(fix: str) -> LidarMount:
    match = re.search(r"--lidar-mount (\S+)$", fix)
    assert match, fix
    mount = parse_mount(match.group(1))
    assert mount is not None
    return mount


@pytest.mark.parametrize("mount", MOUNTS, ids=lambda m: m.option_text())
@pytest.mark.parametrize("invert,offset", DRIVERS)
def test_the_named_lidar_mount_aligns_the_board(
    mount: LidarMount, invert: bool, offset: float
) -> None:
    """If the board is right, the --lidar-mount the fix names makes the same board aligned;
    if the harness's mount is right, the driver settings it names do."""
    truths = _run_scenes(ticks=6)
    fitted = _fit(truths, mount, invert=invert, offset=offset)
    rotation, mirrored = _expected(mount, invert, offset)
    assert fitted.mirrored == mirrored and _same_turn(fitted.rotation_deg, rotation)
    if fitted.status == "aligned":
        assert (invert, mount.yaw_deg % 360) == (not mount.mirrored, offset % 360)
        return
    assert fitted.status == "misaligned", fitted
    # The board is right: emulate with the mount the fix names, same driver.
    again = _fit(truths, _lidar_mount_of(fitted.fix), invert=invert, offset=offset)
    assert again.status == "aligned", (fitted.fix, again)
    # The harness is right: the driver as the fix says.
    if fitted.mirrored:
        fixed = {"invert": not invert, "offset": fitted.rotation_deg - offset}
        assert f"(to {mount.yaw_deg:g} for" in fitted.fix
    else:
        fixed = {"invert": invert, "offset": offset - fitted.rotation_deg}
    assert _fit(truths, mount, **fixed).status == "aligned"


def test_likely_fix_with_no_mount_is_forward() -> None:
    """None is the generic mount: zero straight ahead, clockwise."""
    assert likely_fix(-30.0, False) == likely_fix(-30.0, False, FORWARD)
    assert "30 deg higher (to 0 for" in likely_fix(-30.0, False)
    assert likely_fix(0.0, True).endswith("--lidar-mount 0,mirrored")
    assert "to minus its value" in likely_fix(0.0, True)


# --- over a run ----------------------------------------------------------------------


def _result(truths: list[Scan], boards: list[Scan | None], **fields: object) -> RunResult:
    records = []
    for k, (truth, board) in enumerate(zip(truths, boards, strict=True)):
        answers = Answers(seen=board)
        verdict = Oracle(0.5).judge(k, k * 0.1, board or truth, answers)
        records.append(TickRecord(k, k * 0.1, 0.0, 0.0, 0.0, truth, answers, verdict))
    return RunResult("corner", "rplidar", 0, 0.5, "clean", records=records, **fields)  # type: ignore[arg-type]


def test_run_alignment_uses_the_board_scans_and_the_mount() -> None:
    """Every tick with a board scan, over every scenario; the results' mount for the fix."""
    truths = _run_scenes(ticks=8)
    mount = LidarMount(0.0)
    boards: list[Scan | None] = [_board(t, mount=mount, offset=90.0) for t in truths]
    results = [
        _result(truths[:4], boards[:4], lidar_mount=mount),
        _result(truths[4:], boards[4:], lidar_mount=mount),
    ]
    fitted = run_alignment(results)
    assert fitted is not None and fitted.ticks == 8
    assert (fitted.status, fitted.rotation_deg) == ("misaligned", 90.0)
    assert fitted.fix.endswith("--lidar-mount 90")


def test_run_alignment_without_board_scans_is_none() -> None:
    """The ros2 and inprocess links: the node saw the truth itself, nothing to fit."""
    truths = _run_scenes(ticks=3)
    assert run_alignment([_result(truths, [None] * 3)]) is None
    assert run_alignment([]) is None


def test_a_long_run_fits_a_capped_spread_of_its_ticks() -> None:
    """600 ticks of 720 beams: the fit reads a capped number of ticks, spread over the run
    (what keeps it fast; its speed is the benchmarks' to measure, not a test's)."""
    truths = _run_scenes(ticks=20, layout="720 -pi..pi")
    boards = [_board(t, offset=0.0) for t in truths]
    pairs = [(truths[k % 20], boards[k % 20]) for k in range(600)]
    fitted = fit_alignment(pairs, mount=V2)
    assert fitted is not None and fitted.status == "misaligned" and fitted.ticks < 600
