"""Scan -> device samples: the angle flip, REP-117 values as device distances, resampling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from harness.devices.revolution import Sample, device_angle_deg, samples_from_scan
from harness.lidar.scan import Scan
from harness.lidar.spec import PRESETS


def scan_of(ranges, *, angle_min=0.0, increment=None, range_min=0.15, range_max=12.0) -> Scan:
    ranges = np.asarray(ranges, dtype=np.float32)
    n = ranges.size
    increment = 2 * math.pi / n if increment is None else increment
    return Scan(
        angle_min=angle_min,
        angle_max=angle_min + (n - 1) * increment,
        angle_increment=increment,
        time_increment=0.0,
        scan_time=0.1,
        range_min=range_min,
        range_max=range_max,
        ranges=ranges,
    )


def returns(samples: list[Sample]) -> list[Sample]:
    return [s for s in samples if s.distance_mm > 0]


@pytest.mark.parametrize(
    ("ccw", "device"),
    [(0.0, 0.0), (math.pi / 2, 270.0), (-math.pi / 2, 90.0), (math.pi, 180.0), (-1e-18, 0.0)],
)
def test_device_angle_is_clockwise_degrees(ccw: float, device: float) -> None:
    assert device_angle_deg(ccw) == pytest.approx(device)
    assert 0.0 <= device_angle_deg(ccw) < 360.0


def test_a_return_at_plus_half_pi_shows_up_at_device_270() -> None:
    ranges = np.full(360, np.inf)
    ranges[90] = 1.0  # angle_min 0 + 90 degrees CCW: the robot's left
    [hit] = returns(samples_from_scan(scan_of(ranges)))
    assert hit == Sample(270.0, 1000.0, 47)


def test_samples_run_in_increasing_device_angle_from_zero() -> None:
    for spec in PRESETS.values():
        n = spec.samples
        scan = scan_of(
            np.linspace(0.5, 5.0, n), angle_min=spec.angle_min, increment=spec.angle_increment
        )
        angles = [s.angle_deg for s in samples_from_scan(scan)]
        assert len(angles) == n
        assert angles == sorted(angles)
        assert 0.0 <= angles[0] < 360.0 / n + 1e-9 and angles[-1] < 360.0


def test_rep117_values_become_device_distances() -> None:
    ranges = [math.inf, -math.inf, math.nan, 0.0, -1.0, 0.05, 2.5, 20.0]
    scan = scan_of(ranges, range_min=0.15, range_max=12.0)
    by_angle = {round(s.angle_deg, 6): s.distance_mm for s in samples_from_scan(scan)}
    got = [by_angle[round(device_angle_deg(a), 6)] for a in scan.angles()]
    # inf / -inf / NaN / 0 / negative: no return; 0.05 < range_min is still sent
    # (a spurious short return the driver must filter); beyond range_max too
    # unless the device's own max range is given.
    assert got == pytest.approx([0, 0, 0, 0, 0, 50.0, 2500.0, 20000.0], abs=1e-3)
    capped = samples_from_scan(scan, max_range_m=12.0)
    assert max(s.distance_mm for s in capped) == pytest.approx(2500.0)


def test_quality_is_zero_exactly_when_there_is_no_return() -> None:
    scan = scan_of([math.inf, 1.0, math.nan, 2.0])
    for s in samples_from_scan(scan, quality=33):
        assert (s.quality == 0) == (s.distance_mm == 0) and s.quality in (0, 33)


def test_resampling_takes_the_nearest_beam() -> None:
    ranges = np.arange(1, 361, dtype=np.float64)  # beam i (CCW i degrees) reads i + 1 m
    samples = samples_from_scan(scan_of(ranges), samples_per_rev=720)
    assert [s.angle_deg for s in samples] == pytest.approx([k / 2 for k in range(720)])
    for s in samples:
        beam = round((-s.angle_deg) % 360.0) % 360  # nearest CCW degree (ties: either side)
        options = {ranges[beam], ranges[(beam - 1) % 360], ranges[(beam + 1) % 360]}
        assert s.distance_mm / 1000.0 in options
    assert samples[0].distance_mm == 1000.0  # device 0 = beam 0
    assert samples[180].distance_mm == pytest.approx(271_000.0)  # device 90 = CCW 270


def test_resampling_leaves_uncovered_directions_empty() -> None:
    # A 90-degree sector centred straight ahead: CCW -45..+45 degrees.
    inc = math.radians(1.0)
    scan = scan_of(np.full(91, 3.0), angle_min=-math.pi / 4, increment=inc)
    samples = samples_from_scan(scan, samples_per_rev=360)
    seen = {round(s.angle_deg) for s in returns(samples)}
    assert seen == set(range(0, 46)) | set(range(315, 360))


def test_gazebo_closed_circle_resamples_without_a_gap() -> None:
    spec = PRESETS["gazebo"]  # -pi..pi inclusive: first and last beam coincide
    scan = scan_of(
        np.full(spec.samples, 2.0), angle_min=spec.angle_min, increment=spec.angle_increment
    )
    samples = samples_from_scan(scan, samples_per_rev=450)
    assert len(samples) == 450 and all(s.distance_mm == 2000.0 for s in samples)


def test_resampling_rejects_nonsense() -> None:
    with pytest.raises(ValueError):
        samples_from_scan(scan_of([1.0]), samples_per_rev=0)


@settings(max_examples=60, deadline=None)
@given(
    ranges=hnp.arrays(
        np.float32,
        st.integers(1, 400),
        elements=st.one_of(st.floats(-1, 30, width=32), st.sampled_from([np.inf, -np.inf, np.nan])),
    ),
    angle_min=st.floats(-math.pi, math.pi),
    resample=st.one_of(st.none(), st.integers(1, 800)),
)
def test_any_scan_gives_well_formed_samples(ranges, angle_min, resample) -> None:
    samples = samples_from_scan(scan_of(ranges, angle_min=angle_min), samples_per_rev=resample)
    assert len(samples) == (ranges.size if resample is None else resample)
    angles = [s.angle_deg for s in samples]
    assert angles == sorted(angles) and all(0.0 <= a < 360.0 for a in angles)
    for s in samples:
        assert math.isfinite(s.distance_mm) and s.distance_mm >= 0
        assert (s.quality == 0) == (s.distance_mm == 0)
