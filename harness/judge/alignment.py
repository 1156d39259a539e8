"""Is the board's /scan the robot's view, or that view turned and/or mirrored? (pure)

On the serial links the board's own driver makes the scan, and a driver
set up for another mounting shows every obstacle at another angle while
the verdicts stay self-consistent (the oracle judges the board's scan).
The harness knows each revolution's truth, so it fits the turn and mirror
that carry the truth onto the board's scan over the run (docs/hil.md).

Both scans go onto 1-degree bins (the nearest valid reading each); a turn x
mirror scores the share of bins valid in either scan where both are valid
and agree within 5 cm + 3 % (bins empty in both say nothing). The board
shows the robot's view at ``phi`` at ``(-phi if mirrored else phi) + rotation_deg``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from harness.lidar.mount import FORWARD, LidarMount
from harness.lidar.scan import Scan
from harness.option_names import named

if TYPE_CHECKING:
    from harness.judge.records import RunResult

__all__ = ["STATUSES", "Alignment", "fit_alignment", "likely_fix", "run_alignment", "run_pairs"]

STATUSES = ("aligned", "misaligned", "unknown")
GRID = 360  # bins of 1 degree: the fit's resolution
ABS_TOLERANCE_M = 0.05
REL_TOLERANCE = 0.03
MAX_TICKS = 240  # ticks fitted at most, evenly spread over the run (speed)
CHUNK = 16  # ticks scored at once (memory: CHUNK x 360 x 360 floats)
MIN_VALID_BINS = 20  # valid bins, in each of truth and board, below which nothing is told
MIN_AGREEMENT = 0.5  # below this share the board's scan is not the truth in any turn
MARGIN = 0.05  # the best must beat the runner-up that differs by this share
NEAR_DEG = 5  # turns this close to the best (same mirror) are the same answer
ALIGNED_DEG = 2  # |rotation| up to this is aligned: binning shifts a beam by up to a bin
ROUND_DEG = 5  # a fitted turn within SNAP_DEG of a multiple of this is taken as that multiple
SNAP_DEG = 1.0
ROUND_SCENE = 36  # this many other turns and mirrors as good as the best: a round scene


@dataclass(frozen=True)
class Alignment:
    """The fitted turn and mirror of the board's /scan against the truth, and what to change."""

    rotation_deg: float  # board angle of scan angle phi: (-phi if mirrored else phi) + this
    mirrored: bool
    status: str  # "aligned", "misaligned" or "unknown" (the run's scenes cannot tell)
    ticks: int  # ticks the fit used
    agreement: float  # share of compared beams that agree under the best fit
    identity_agreement: float  # the same share as shown: no turn, no mirror
    fix: str = ""  # one line: the likely fix (empty unless misaligned)
    reason: str = ""  # why it cannot tell (only when unknown)

    @property
    def misaligned(self) -> bool:
        return self.status == "misaligned"

    def describe(self) -> str:
        """'the board's /scan is the robot's view turned by +90 deg' (or mirrored, or both)."""
        return _describe(self.mirrored, self.rotation_deg)

    def text(self) -> str:
        """One line for the terminal and the page."""
        if self.status == "unknown":
            return f"cannot tell: {self.reason} ({_ticks(self.ticks)})"
        if self.status == "aligned":
            return (
                "the board's /scan matches the robot's view "
                f"({_percent(self.agreement)} of compared beams agree; {_ticks(self.ticks)})"
            )
        stats = (
            f"{_percent(self.agreement)} of compared beams agree so, "
            f"{_percent(self.identity_agreement)} as shown; {_ticks(self.ticks)}"
        )
        action = self.fix.removeprefix(f"{self.describe()}: ")
        return f"{self.describe()} ({stats}): {action}"


def _percent(share: float) -> str:
    return f"{100.0 * share:.0f} %"


def _ticks(n: int) -> str:
    return f"{n} tick{'s' if n != 1 else ''}"


def _normalised(deg: float) -> float:
    """An angle in degrees in (-180, 180]."""
    turned = -((-deg + 180.0) % 360.0) + 180.0
    return turned + 0.0  # no -0.0


def _transform(mirrored: bool, rotation_deg: float) -> str:
    """'as shown', 'turned by +90 deg', 'mirrored', 'mirrored and turned by -37 deg'."""
    turn = f"turned by {rotation_deg:+g} deg" if rotation_deg else ""
    if mirrored:
        return f"mirrored and {turn}" if turn else "mirrored"
    return turn or "as shown"


def _describe(mirrored: bool, rotation_deg: float) -> str:
    return f"the board's /scan is the robot's view {_transform(mirrored, rotation_deg)}"


def likely_fix(rotation_deg: float, mirrored: bool, mount: LidarMount | None = None) -> str:
    """What to change so that the board shows the robot's view: the board driver's
    (invert, angle_offset_deg) if the harness's mount is right, else the harness's mount.

    A driver maps device angle theta to ``(-theta if invert else theta) + offset``;
    the harness sends scan angle phi at device angle ``yaw - phi`` (``phi - yaw``
    when mirrored). So a board with ``invert == mount.mirrored`` shows the view
    mirrored, turned by ``offset + yaw``; otherwise turned by ``offset - yaw``.
    """
    mount = mount if mount is not None else FORWARD
    yaw = _normalised(mount.yaw_deg)
    harness = f"the harness's mount: {mount.describe()}"
    if not mirrored:
        way = "lower" if rotation_deg > 0 else "higher"
        driver = (
            f"set the board driver's angle_offset_deg {abs(rotation_deg):g} deg {way} "
            f"(to {yaw:g} for {harness})"
        )
        board_mount = LidarMount(_normalised(yaw + rotation_deg), mount.mirrored)
    else:
        value = f"{rotation_deg:g} minus its current value" if rotation_deg else "minus its value"
        driver = (
            "flip the board driver's invert and set its angle_offset_deg to "
            f"{value} (to {yaw:g} for {harness})"
        )
        board_mount = LidarMount(_normalised(rotation_deg - yaw), not mount.mirrored)
    return (
        f"{_describe(mirrored, rotation_deg)}: {driver}, or if the board is right, "
        f"run with {named('lidar_mount')} {board_mount.option_text()}"
    )


def _window(truth: Scan, board: Scan) -> tuple[float, float]:
    """The ranges both scans can report: a reading outside one's limits says nothing."""
    lo = max(float(truth.range_min), float(board.range_min))
    hi = min(float(truth.range_max), float(board.range_max))
    return lo, hi


def _grid(scan: Scan, lo: float, hi: float) -> np.ndarray:
    """The scan on the 1-degree grid by angle: the nearest valid reading per bin, else NaN."""
    ranges = scan.ranges.astype(np.float64)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= lo) & (ranges <= hi)
    degrees = np.degrees(scan.angles()[valid])
    index = np.floor(degrees + 0.5).astype(np.int64) % GRID
    out = np.full(GRID, np.inf)
    np.minimum.at(out, index, ranges[valid])
    out[np.isinf(out)] = np.nan
    return _fill_holes(out)


def _fill_holes(grid: np.ndarray) -> np.ndarray:
    """A lone empty bin between two that agree takes their mean (floor binning's artefact)."""
    before, after = np.roll(grid, 1), np.roll(grid, -1)
    with np.errstate(invalid="ignore"):
        alike = np.abs(before - after) <= ABS_TOLERANCE_M + REL_TOLERANCE * np.fmin(before, after)
    hole = np.isnan(grid) & alike
    filled = grid.copy()
    filled[hole] = 0.5 * (before[hole] + after[hole])
    return filled


def _mirror(board: np.ndarray) -> np.ndarray:
    """Rows with bin j holding bin -j: a turn of this is a mirrored turn of the original."""
    return np.roll(board[:, ::-1], 1, axis=1)


def _scores(truth: np.ndarray, board: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per turn r (bins): beams that agree, and beams valid in either scan, summed over rows.

    Turn r compares truth bin i with board bin (i + r) mod GRID.
    """
    agree = np.zeros(GRID, np.int64)
    both = np.zeros(GRID, np.int64)
    tolerance = ABS_TOLERANCE_M + REL_TOLERANCE * truth
    for start in range(0, len(truth), CHUNK):
        t = truth[start : start + CHUNK, None, :].astype(np.float32)
        tol = tolerance[start : start + CHUNK, None, :].astype(np.float32)
        twice = np.concatenate([board[start : start + CHUNK]] * 2, axis=1).astype(np.float32)
        turned = np.lib.stride_tricks.sliding_window_view(twice, GRID, axis=1)[:, :GRID, :]
        gap = np.abs(turned - t)  # NaN where either has nothing
        agree += (gap <= tol).sum(axis=(0, 2))
        both += np.isfinite(gap).sum(axis=(0, 2))
    valid = int(np.isfinite(truth).sum()) + int(np.isfinite(board).sum())
    return agree, valid - both


def _evenly(items: Sequence[tuple[Scan, Scan]], cap: int) -> list[tuple[Scan, Scan]]:
    """At most `cap` of the items, evenly spread (first and last kept)."""
    if len(items) <= cap:
        return list(items)
    picks = np.unique(np.linspace(0, len(items) - 1, cap).round().astype(int))
    return [items[i] for i in picks]


def _refined(row: np.ndarray, turn: int) -> float:
    """The turn in degrees, from the peak of one mirror's scores.

    A board binning by floor shows each beam up to a bin early, so the peak
    falls between two turns: a parabola's vertex is the better estimate, and a
    turn within a degree of a multiple of 5 (what a setting is made of) is that.
    """
    before, peak, after = (float(row[(turn + d) % GRID]) for d in (-1, 0, 1))
    curve = before - 2.0 * peak + after
    shift = 0.5 * (before - after) / curve if curve < 0.0 else 0.0
    estimate = turn + max(-0.5, min(0.5, shift))
    rounded = ROUND_DEG * round(estimate / ROUND_DEG)
    whole = rounded if abs(estimate - rounded) <= SNAP_DEG else round(estimate)
    return _normalised(float(whole))


def fit_alignment(
    pairs: Iterable[tuple[Scan, Scan]], *, mount: LidarMount | None = None
) -> Alignment | None:
    """The turn and mirror that best carry the truth onto the board's scan, over
    (truth, board) pairs; None without pairs. `mount`: the one the device was
    emulated with (None: forward), for the fix."""
    used = _evenly(list(pairs), MAX_TICKS)
    if not used:
        return None
    grids = [(_grid(t, *_window(t, b)), _grid(b, *_window(t, b))) for t, b in used]
    truth, board = (np.array(side) for side in zip(*grids, strict=True))
    plain_agree, plain_union = _scores(truth, board)
    mirror_agree, mirror_union = _scores(truth, _mirror(board))
    # Mirrored turn R compares truth bin i with board bin (R - i): the mirrored rows at -R.
    back = (-np.arange(GRID)) % GRID
    agree = np.stack([plain_agree, mirror_agree[back]])
    union = np.stack([plain_union, mirror_union[back]])
    shares = agree / np.maximum(union, 1)
    return _judge(shares, truth, board, len(used), mount)


def _judge(
    shares: np.ndarray, truth: np.ndarray, board: np.ndarray, ticks: int, mount: LidarMount | None
) -> Alignment:
    """The verdict on the scores of every (mirror, turn): aligned, misaligned or unknown."""
    mirror, turn = np.unravel_index(int(np.argmax(shares)), shares.shape)
    best = float(shares[mirror, turn])
    rotation = _refined(shares[mirror], int(turn))
    found = {
        "rotation_deg": rotation,
        "mirrored": bool(mirror),
        "ticks": ticks,
        "agreement": round(best, 4),
        "identity_agreement": round(float(shares[0, 0]), 4),
    }
    informative = min(int(np.isfinite(truth).sum()), int(np.isfinite(board).sum()))
    if informative < MIN_VALID_BINS:
        reason = "too little in range to compare (the run's scenes, or the board's scans)"
        return Alignment(status="unknown", reason=reason, **found)
    if best < MIN_AGREEMENT:
        reason = (
            f"the board's /scan matches the robot's view in no turn "
            f"(at best {_percent(best)} of compared beams agree)"
        )
        return Alignment(status="unknown", reason=reason, **found)
    alike = _look_alike(shares, int(mirror), int(turn), rotation)
    if alike:
        return Alignment(status="unknown", reason=alike, **found)
    if not mirror and abs(rotation) <= ALIGNED_DEG:
        return Alignment(status="aligned", **found)
    return Alignment(status="misaligned", fix=likely_fix(rotation, bool(mirror), mount), **found)


def _look_alike(shares: np.ndarray, mirror: int, turn: int, rotation: float) -> str:
    """Why the best answer is not clearly the answer ('' when it is): another one,
    the other mirror or a turn more than NEAR_DEG away, scores within MARGIN of it."""
    distance = np.abs((np.arange(GRID) - turn + GRID // 2) % GRID - GRID // 2)
    others = shares.copy()
    others[mirror, distance <= NEAR_DEG] = -1.0  # the best answer's own neighbourhood
    second, turn2 = (int(i) for i in np.unravel_index(int(np.argmax(others)), others.shape))
    best, runner = float(shares[mirror, turn]), float(others[second, turn2])
    if best - runner >= MARGIN:
        return ""
    other = _transform(bool(second), _normalised(float(turn2)))
    named = f"{_transform(bool(mirror), rotation)} and {other}"
    agree = f"{_percent(best)} and {_percent(runner)} of compared beams agree"
    if (others > best - MARGIN).sum() >= ROUND_SCENE:
        return f"the run's scenes look alike whichever way they are turned (e.g. {named}: {agree})"
    return f"the run's scenes look alike {named} ({agree})"


def run_pairs(results: Sequence[RunResult]) -> list[tuple[Scan, Scan]]:
    """(truth, board) for every tick whose board scan is known (the serial links)."""
    return [
        (record.scan, record.answers.seen)
        for result in results
        for record in result.records
        if record.answers.seen is not None
    ]


def run_alignment(results: Sequence[RunResult]) -> Alignment | None:
    """The fit over a whole run; None when no tick has a board scan (ros2, inprocess).

    A revolution published late or split (``answers.earlier``) is left out: its
    truth is not known for sure. One device per run: the first mount named.
    """
    mount = next((r.lidar_mount for r in results if r.lidar_mount is not None), None)
    return fit_alignment(run_pairs(results), mount=mount)
