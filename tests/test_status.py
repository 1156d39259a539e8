"""Status parsing: the many ways students word 'obstacle at d m, angle a rad'."""

from __future__ import annotations

import math
import re

import pytest

from harness.errors import ConfigError
from harness.judge.status import half_unit, parse_status
from harness.judge.status_numbers import find_numbers

INF, NAN = math.inf, math.nan
NONE = (False, None, None)

# text -> (obstacle claimed, distance, angle)
WORDINGS: list[tuple[str, tuple[bool, float | None, float | None]]] = [
    # the lab's own wording and close variants
    ("No obstacle", NONE),
    ("no obstacle detected", NONE),
    ("No obstacles in range", NONE),
    ("NO_OBSTACLE", NONE),
    ("Obstacle: False", NONE),
    ("obstacle_detected=False min_dist=inf", NONE),
    ("Obstacle detected: no", NONE),
    ("Nothing detected", NONE),
    ("nothing within 0.5 m", NONE),
    ("All clear", NONE),
    ("Path is clear (min=inf)", NONE),
    ("Path free", NONE),
    ("none detected", NONE),
    ("Obstacle out of range", NONE),
    ("Obstacle not detected", NONE),
    ("No valid readings", NONE),
    ("Brak przeszkody", NONE),
    ("Obstacle: None, distance: None", NONE),
    ("Obstacle detected", NONE),  # no number: nothing to judge as a claim
    ("", NONE),
    # obstacle claims
    ("Obstacle detected! Min distance: 0.84", (True, 0.84, None)),
    ("Obstacle at 0.84 m, angle 1.57 rad", (True, 0.84, 1.57)),
    ("Obstacle detected at 0.842m, angle -0.52rad", (True, 0.842, -0.52)),
    ("d=0.84,a=1.57", (True, 0.84, 1.57)),
    ("distance=1.2e-1 angle=-3.1e+0", (True, 0.12, -3.1)),
    ("(0.8420000076293945, 1.5707963267948966)", (True, 0.8420000076293945, 1.5707963267948966)),
    ("np.float32(0.84) np.float32(1.57)", (True, 0.84, 1.57)),
    ("Min distance: 0.84, Angle: 1.5707963267948966", (True, 0.84, 1.5707963267948966)),
    ("Angle: 1.57 rad, distance: 0.84 m", (True, 0.84, 1.57)),  # labels beat order
    ("1.57 rad 0.84 m", (True, 0.84, 1.57)),
    ("Obstacle at index 90: 0.84 m, 1.57 rad", (True, 0.84, 1.57)),
    ("t=3.2s obstacle at 0.5 m, angle 0.1", (True, 0.5, 0.1)),
    ("LIDAR2: obstacle at 0.5, 0.25", (True, 0.5, 0.25)),
    ("/scan2 -> 0.31 m, 0.0 rad", (True, 0.31, 0.0)),
    ("A1M8 float32 reading .5", (True, 0.5, None)),
    ("v1.2.3 obstacle 0.7", (True, 0.7, None)),
    ("Obstacle [0.5, 1.0]", (True, 0.5, 1.0)),
    ("Nearest obstacle is not far: 0.9 m", (True, 0.9, None)),
    ("Path not clear: obstacle at 0.4 m", (True, 0.4, None)),
    ("Clearance 0.42 m", (True, 0.42, None)),
    ("No warning. Obstacle at 0.8 m, 0.3 rad", (True, 0.8, 0.3)),
    ("Warning: False, obstacle at 2.5 m", (True, 2.5, None)),
    ("Free space ahead: 1.2 m", (True, 1.2, None)),
    ("OBSTACLE 0.84 90°", (True, 0.84, 90.0)),  # degrees are read, and judged wrong later
    ("Obstacle at 84 cm, 90 deg", (True, 84.0, 90.0)),  # units are never converted
    ("Odległość: 0.84 m, kąt: 1.57 rad", (True, 0.84, 1.57)),
    ("min_dist=0.84 angle_rad=-1.57", (True, 0.84, -1.57)),
    ("Obstacle 1.57, distance 0.84", (True, 0.84, 1.57)),
    ("info: 0.5", (True, 0.5, None)),  # "info" is not inf
    # inf / nan are numbers: an obstacle claim, wrong when there is one
    ("Min distance: inf", (True, INF, None)),
    ("Min distance: nan", (True, NAN, None)),
    ("Min distance: -inf", (True, -INF, None)),
    ("Distance: +INF m", (True, INF, None)),
    ("dist Infinity angle NaN", (True, INF, NAN)),
    ("Obstacle at inf m, angle 0.0", (True, INF, 0.0)),
]


def _same(a: float | None, b: float | None) -> bool:
    if a is None or b is None:
        return a is b
    return a == b or (math.isnan(a) and math.isnan(b))


@pytest.mark.parametrize("text, expected", WORDINGS, ids=[w or "<empty>" for w, _ in WORDINGS])
def test_wordings(text: str, expected: tuple[bool, float | None, float | None]) -> None:
    """Each wording yields the claim a reader would take from it."""
    claim = parse_status(text)
    obstacle, distance, angle = expected
    assert claim.text == text
    assert claim.obstacle is obstacle
    assert _same(claim.distance, distance), claim
    assert _same(claim.angle, angle), claim


def test_no_obstacle_reason() -> None:
    """A 'no obstacle' claim says why, for explanations."""
    assert parse_status("No obstacle (min=inf)").reason == "says 'No obstacle'"
    assert parse_status("Obstacle detected").reason == "no number"
    assert parse_status("Obstacle at 0.5").reason is None


@pytest.mark.parametrize(
    "text, dd, ad",
    [
        ("0.84 1.57", 2, 2),
        ("0.842m -0.5rad", 3, 1),
        ("1 2", 0, 0),
        ("1.2e-1 3e2", 2, -2),
        ("5. .25", 0, 2),
        ("inf nan", None, None),
        ("0.8420000076293945 3.0", 16, 1),
    ],
)
def test_printed_decimals(text: str, dd: int | None, ad: int | None) -> None:
    """Printed precision counts digits after the point, less the exponent."""
    claim = parse_status(text)
    assert (claim.distance_decimals, claim.angle_decimals) == (dd, ad)


def test_half_unit() -> None:
    """Half a unit in the last printed digit."""
    assert half_unit(2) == pytest.approx(0.005)
    assert half_unit(0) == 0.5
    assert half_unit(-1) == 5.0
    assert half_unit(None) == 0.0


@pytest.mark.parametrize(
    "text, values",
    [
        ("LIDAR2 LD06 /scan2 float32 A1M8 x_3", []),
        ("version 1.2.3", []),
        ("info nanosec infinite", []),
        ("a-1 (-2) [+3]", [1.0, -2.0, 3.0]),
        ("0.84,1.57;2", [0.84, 1.57, 2.0]),
        ("Scan done. 0.5", [0.5]),
    ],
)
def test_number_boundaries(text: str, values: list[float]) -> None:
    """Digits glued to words, paths or versions are not numbers."""
    assert [n.value for n in find_numbers(text)] == values


def test_number_labels() -> None:
    """Units after and keywords before a number label it."""
    labels = [n.label for n in find_numbers("idx 3, t=0.1s: dist 0.8, 1.5 rad, 2 Hz, 7")]
    assert labels == ["ignore", "ignore", "distance", "angle", "ignore", None]


# -- user patterns -----------------------------------------------------------


def test_user_pattern_overrides() -> None:
    """Named groups distance/angle replace the default rules."""
    pattern = r"D\[(?P<distance>[^\]]*)\] A\[(?P<angle>[^\]]*)\]"
    claim = parse_status("t=9 D[0.84] A[1.5708]", pattern)
    assert (claim.obstacle, claim.distance, claim.angle) == (True, 0.84, 1.5708)
    assert (claim.distance_decimals, claim.angle_decimals) == (2, 4)
    miss = parse_status("no match here 0.5", pattern)
    assert not miss.obstacle and miss.reason == "the pattern does not match"


def test_user_pattern_obstacle_group() -> None:
    """An obstacle group decides the claim; falsy words mean 'no obstacle'."""
    pattern = re.compile(r"obst=(?P<obstacle>\w+)(?: d=(?P<distance>\S+))?(?: a=(?P<angle>\S+))?")
    yes = parse_status("obst=1 d=0.5 a=0.1", pattern)
    assert (yes.obstacle, yes.distance, yes.angle) == (True, 0.5, 0.1)
    for falsy in ("False", "no", "0", "none"):
        claim = parse_status(f"obst={falsy} d=inf", pattern)
        assert not claim.obstacle and claim.reason == f"obstacle group {falsy!r}"


def test_user_pattern_without_obstacle_group() -> None:
    """Without an obstacle group, a distance means an obstacle claim."""
    claim = parse_status("free", r"(?P<distance>\d+\.\d+)?")
    assert not claim.obstacle


@pytest.mark.parametrize(
    "pattern, message",
    [
        (r"(?P<distance>[0-9.+", r"status pattern .*: bad regex"),
        (r"(?P<angle>\d+)", r"needs a named group \(\?P<distance>"),
    ],
)
def test_bad_patterns(pattern: str, message: str) -> None:
    """A broken or incomplete regex is the user's to fix: ConfigError."""
    with pytest.raises(ConfigError, match=message):
        parse_status("x", pattern)
