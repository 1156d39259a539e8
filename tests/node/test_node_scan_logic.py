"""The reference node's pure logic: REP-117 validity, the lab's angle, the warning, the text."""

from __future__ import annotations

import array
import math
import random
import re
from dataclasses import FrozenInstanceError

import numpy as np
import pytest

from harness.reference.scan_logic import (
    ObstacleReport,
    analyse_scan,
    check_threshold,
    status_text,
)

INF, NAN = math.inf, math.nan
DEG = math.radians(1.0)
# The Gazebo-like preset (FACTS): 360 beams over -pi..pi, 0.12-12 m.
GAZEBO = {"angle_min": -math.pi, "angle_increment": DEG, "range_min": 0.12, "range_max": 12.0}
# The FOSSBot bridge: 360 beams from 0, 0.15-12 m.
BRIDGE = {"angle_min": 0.0, "angle_increment": DEG, "range_min": 0.15, "range_max": 12.0}


def analyse(ranges, threshold: float = 0.5, **header: float) -> ObstacleReport:
    """analyse_scan with the Gazebo-like header unless a field is overridden."""
    return analyse_scan(ranges, threshold=threshold, **{**GAZEBO, **header})


def reference(ranges, angle_min, angle_increment, range_min, range_max, threshold):
    """A slow, obvious per-beam loop: the specification the numpy code must match."""
    best = None
    for i, r in enumerate(ranges):
        if math.isfinite(r) and range_min <= r <= range_max:
            if best is None or r < ranges[best]:
                best = i
    if best is None:
        return ObstacleReport(False, None, None, None, False)
    distance = ranges[best]
    return ObstacleReport(
        True, distance, angle_min + best * angle_increment, best, distance < threshold
    )


def test_all_no_return_is_no_obstacle() -> None:
    """The lab's pitfall: a scan of +inf is "no obstacle", never a distance of inf."""
    report = analyse(array.array("f", [INF] * 360))
    assert report == ObstacleReport(False, None, None, None, False)
    assert status_text(report) == "No obstacle detected"


@pytest.mark.parametrize(
    "invalid",
    [INF, -INF, NAN, 0.0, 0.05, 12.5, -1.0],
    ids=[
        "+inf no return",
        "-inf too close",
        "nan error",
        "zero no return",
        "below range_min",
        "above range_max",
        "negative",
    ],
)
def test_invalid_reading_never_wins(invalid: float) -> None:
    """Each REP-117 or driver "no reading" value is ignored, even where it is the smallest."""
    report = analyse([invalid, 3.0, invalid])
    assert (report.obstacle, report.distance, report.index) == (True, 3.0, 1)
    assert not analyse([invalid] * 4).obstacle


def test_bounds_are_inclusive() -> None:
    """Readings equal to range_min or range_max are valid (REP-117 invalid is < or >)."""
    assert analyse([INF, 0.12, INF]).distance == pytest.approx(0.12)
    report = analyse([INF, 12.0, INF])
    assert (report.obstacle, report.distance, report.index) == (True, 12.0, 1)


def test_range_max_driver_convention() -> None:
    """A driver writing range_max for "no return" reads as an obstacle at range_max (as the
    oracle's REP-117 rule says); one writing just beyond range_max reads as none."""
    assert analyse([12.0] * 360).distance == 12.0
    assert not analyse([np.nextafter(np.float32(12.0), np.float32(13.0))] * 360).obstacle


def test_float32_bounds_compare_as_in_the_message() -> None:
    """A float32 reading equal to the float32 range_min in the message is valid, whether the
    bound arrives as the message's float32 value or as the decimal it was written from."""
    reading = array.array("f", [0.15])
    assert analyse(reading, **BRIDGE).obstacle
    assert analyse(reading, **{**BRIDGE, "range_min": float(np.float32(0.15))}).obstacle


@pytest.mark.parametrize("index", [0, 1, 90, 180, 270, 359])
@pytest.mark.parametrize("header", [GAZEBO, BRIDGE], ids=["angle_min=-pi", "angle_min=0"])
def test_angle_is_the_labs_formula_unwrapped(index: int, header: dict[str, float]) -> None:
    """angle = angle_min + index * angle_increment exactly, with no wrap into (-pi, pi]."""
    ranges = [INF] * 360
    ranges[index] = 1.0
    report = analyse_scan(ranges, threshold=0.5, **header)
    assert report.index == index
    assert report.angle == header["angle_min"] + index * header["angle_increment"]


def test_angle_at_index_270_from_zero_is_not_wrapped() -> None:
    """From angle_min 0 the 270th beam is 3*pi/2 (4.712), not -pi/2."""
    ranges = [INF] * 360
    ranges[270] = 2.0
    assert analyse_scan(ranges, threshold=0.5, **BRIDGE).angle == pytest.approx(1.5 * math.pi)


def test_ties_pick_the_first_index() -> None:
    """Among equal minima the first beam wins, also across invalid beams between them."""
    assert analyse([2.0, 1.0, 1.0, 1.0]).index == 1
    assert analyse([NAN, 0.7, INF, 0.0, 0.7]).index == 1


def test_warning_is_strict() -> None:
    """distance < threshold warns; exactly the threshold does not."""
    assert analyse([0.5], threshold=0.5).warning is False
    assert analyse([0.4999], threshold=0.5).warning is True
    assert analyse([0.5001], threshold=0.5).warning is False


def test_warning_uses_the_float32_reading_as_received() -> None:
    """float32(0.4) is 0.4000000059..., so against a threshold of 0.4 it does not warn."""
    assert analyse(array.array("f", [0.4]), threshold=0.4).warning is False
    assert analyse(array.array("f", [0.4]), threshold=0.41).warning is True


def test_no_obstacle_never_warns() -> None:
    """Invalid readings below the threshold (0.0, -inf) raise no warning."""
    assert analyse([0.0, -INF, 0.05], threshold=0.5).warning is False


def test_status_text_format() -> None:
    """Three decimals, distance first and angle second, in metres and radians."""
    report = analyse_scan([0.842], 0.524, 0.0, 0.1, 12.0, 0.5)
    assert status_text(report) == "Min distance: 0.842 m, angle: 0.524 rad"
    first = analyse([0.12345] + [INF] * 359)
    assert status_text(first) == "Min distance: 0.123 m, angle: -3.142 rad"


def test_status_text_reads_back_with_the_default_parser_rule() -> None:
    """The first number is the distance and the second the angle (DESIGN: status strings)."""
    ranges = [INF] * 360
    ranges[45] = 1.2345
    report = analyse(ranges)
    numbers = [float(x) for x in re.findall(r"[-+]?\d+(?:\.\d+)?", status_text(report))]
    assert numbers == [
        pytest.approx(report.distance, abs=5e-4),
        pytest.approx(report.angle, abs=5e-4),
    ]


RANGES = [INF, 2.5, NAN, 0.75, 0.0, 0.75, -INF]
EXPECTED = (True, 0.75, 3)


@pytest.mark.parametrize(
    "ranges",
    [
        array.array("f", RANGES),
        array.array("d", RANGES),
        list(RANGES),
        tuple(RANGES),
        np.array(RANGES, dtype=np.float32),
        np.array(RANGES, dtype=np.float64),
    ],
    ids=["array('f')", "array('d')", "list", "tuple", "numpy float32", "numpy float64"],
)
def test_input_types_agree(ranges) -> None:
    """A LaserScan's array.array('f'), lists, tuples and numpy arrays give one answer."""
    report = analyse(ranges)
    assert (report.obstacle, report.distance, report.index) == EXPECTED
    assert isinstance(report.distance, float) and isinstance(report.index, int)


def test_integer_ranges_are_accepted() -> None:
    """Integer readings (e.g. a hand-written list) are read as metres."""
    assert analyse([5, 3, 4]).distance == 3.0


@pytest.mark.parametrize(
    "empty", [[], array.array("f"), np.zeros(0, np.float32)], ids=["list", "array", "numpy"]
)
def test_empty_scan_is_no_obstacle(empty) -> None:
    """A scan with no beams reports no obstacle instead of failing."""
    assert not analyse(empty).obstacle


def test_two_dimensional_ranges_are_refused() -> None:
    """ranges is one row of beams; anything else is a caller error."""
    with pytest.raises(ValueError, match="one-dimensional"):
        analyse(np.ones((2, 3)))


def test_input_is_not_modified() -> None:
    """The zero-copy view of a message's ranges must not write into the message."""
    ranges = array.array("f", RANGES)
    before = ranges.tobytes()
    analyse(ranges)
    assert ranges.tobytes() == before


def random_reading(rng: random.Random) -> float:
    """A special value (40 %), a repeated round value (for ties), or any distance."""
    roll = rng.random()
    if roll < 0.4:
        return rng.choice([INF, -INF, NAN, 0.0, 0.01, 12.0, 12.5])
    if roll < 0.55:
        return rng.choice([0.3, 0.5, 1.0, 2.0, 7.5])
    return rng.uniform(0.0, 13.0)


def test_matches_the_slow_reference_on_random_scans() -> None:
    """Seeded random scans mixing every invalid kind agree with the per-beam loop."""
    rng = random.Random(7)
    for _ in range(300):
        values = [random_reading(rng) for _ in range(rng.randint(0, 40))]
        # float32-exact values and bounds, as a LaserScan carries them.
        values = [float(np.float32(v)) for v in values]
        header = {
            "angle_min": rng.choice([-math.pi, 0.0, -1.0]),
            "angle_increment": rng.choice([DEG, 0.5 * DEG, 0.0175]),
            "range_min": float(np.float32(rng.choice([0.0, 0.12, 0.15]))),
            "range_max": float(np.float32(rng.choice([8.0, 12.0]))),
            "threshold": rng.choice([0.3, 0.5, 1.0]),
        }
        expected = reference(values, **header)
        assert analyse_scan(array.array("f", values), **header) == expected
        assert analyse_scan(values, **header) == expected


def test_report_is_immutable() -> None:
    """Reports are values: nothing downstream can change one after the fact."""
    report = analyse([1.0])
    with pytest.raises(FrozenInstanceError):
        report.distance = 2.0  # type: ignore[misc]


@pytest.mark.parametrize("value", [0.5, 1, 0.01, 12.0])
def test_check_threshold_accepts_positive_numbers(value: float) -> None:
    """Any finite positive number, integer or float, is a threshold in metres."""
    assert check_threshold(value) == float(value)


@pytest.mark.parametrize(
    ("value", "match"),
    [
        (0.0, "> 0"),
        (-0.4, "> 0"),
        (NAN, "> 0"),
        (INF, "> 0"),
        (True, "number"),
        ("0.4", "number"),
        (None, "number"),
    ],
)
def test_check_threshold_refuses_unusable_values(value: object, match: str) -> None:
    """Zero, negative, NaN, inf, bools and text are refused with a reason."""
    with pytest.raises(ValueError, match=match):
        check_threshold(value)
