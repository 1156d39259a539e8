"""Device angles to CCW bins, nearest-in-bin and range filtering: pure, no ROS."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fossbot_lidar_driver.binning import (
    bin_indices,
    ld_ranges,
    nearest_per_bin,
    rplidar_ranges,
    scan_angle_max,
    scan_increment,
)

INF, NAN = math.inf, math.nan
Q6_ANGLES = np.arange(360 * 64) / 64.0  # every angle an RPLIDAR can send


def bridge_bin(angle_deg: float, bins: int, invert: bool, offset_deg: float) -> int | None:
    """The lab bridge's rule, written out as its lidar_node does it (None: dropped)."""
    step = 2.0 * math.pi / bins
    a = math.radians(angle_deg)
    if invert:
        a = -a
    a += math.radians(offset_deg)
    index = int((a % (2.0 * math.pi)) / step)
    return index if 0 <= index < bins else None


@pytest.mark.parametrize(
    ("device_deg", "expected"),
    [(0.0, 0), (90.0, 270), (270.0, 90), (180.0, 180), (359.6, 0), (0.4, 0), (1.0, 359)],
)
def test_clockwise_device_angle_lands_in_the_counter_clockwise_bin(device_deg, expected) -> None:
    """Nearest mode: bin k holds what the device saw at clockwise -k degrees."""
    assert bin_indices(np.array([device_deg]), 360).tolist() == [expected]


def test_nearest_bin_is_centred_on_its_labelled_angle() -> None:
    """Half a bin either side of k*increment goes to k; exact halves go up."""
    ccw = np.array([9.5, 10.0, 10.49, 10.5])
    assert bin_indices(360.0 - ccw, 360).tolist() == [10, 10, 10, 11]


def test_samples_at_every_labelled_angle_round_trip_for_450_bins() -> None:
    """An emulator that sends bin k at clockwise -k * 0.8 degrees gets bin k back."""
    k = np.arange(450)
    device = np.mod(-k * 0.8, 360.0)
    assert bin_indices(device, 450).tolist() == k.tolist()


def test_invert_false_and_offset() -> None:
    """invert:=false keeps the device's direction; the offset is added after negation."""
    angles = np.array([0.0, 90.0])
    assert bin_indices(angles, 360, invert=False).tolist() == [0, 90]
    assert bin_indices(angles, 360, angle_offset_deg=-90.0).tolist() == [270, 180]


@pytest.mark.parametrize(("invert", "offset"), [(True, 0.0), (True, -90.0), (False, 12.5)])
def test_floor_mode_is_the_bridge_bit_for_bit(invert: bool, offset: float) -> None:
    """floor mode equals the bridge's own arithmetic on every RPLIDAR angle."""
    index = bin_indices(Q6_ANGLES, 360, invert=invert, angle_offset_deg=offset, mode="floor")
    expected = [bridge_bin(a, 360, invert, offset) for a in Q6_ANGLES.tolist()]
    assert [None if i == 360 else i for i in index.tolist()] == expected


def test_unknown_bin_mode_is_refused() -> None:
    """A typo in bin_mode is an error that names the choices."""
    with pytest.raises(ValueError, match="nearest.*floor"):
        bin_indices(np.array([0.0]), 360, mode="round")


def test_layout_matches_the_bridge() -> None:
    """angle_max is 2*pi minus one increment (the bridge's header)."""
    assert scan_increment(360) == pytest.approx(math.radians(1.0))
    assert scan_angle_max(360) == pytest.approx(2 * math.pi - math.radians(1.0))


def test_nearest_reading_wins_and_nan_never_beats_a_number() -> None:
    """fmin per bin: the smallest number; NaN only where only NaNs fell."""
    index = np.array([0, 0, 1, 1, 2, 4])
    ranges = np.array([2.0, 1.0, NAN, 3.0, NAN, 5.0])
    # index 4 == bins means "no bin": skipped.
    np.testing.assert_array_equal(nearest_per_bin(index, ranges, 4, NAN), [1.0, 3.0, NAN, NAN])
    np.testing.assert_array_equal(nearest_per_bin(index, ranges, 4, INF), [1.0, 3.0, INF, INF])


def test_rplidar_drops_no_returns_and_out_of_limit_readings() -> None:
    """Distance 0 and readings outside [range_min, range_max] leave the bin +inf."""
    angles = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
    distances = np.array([0.0, 149.75, 150.0, 12000.0, 12000.25, 1000.0])
    out = rplidar_ranges(angles, distances, 360, range_min=0.15, range_max=12.0)
    finite = {i: float(v) for i, v in enumerate(out) if math.isfinite(v)}
    assert finite == {358: 0.15, 357: 12.0, 355: 1.0}


def test_rplidar_rounds_as_the_lab_agent_sends_json() -> None:
    """0.01 degree and 0.1 mm, half to even: 1234.25 mm is 1.2342 m."""
    out = rplidar_ranges(
        np.array([330.0]), np.array([1234.25]), 360, range_min=0.15, range_max=12.0
    )
    assert out[30] == pytest.approx(1.2342, abs=1e-12)


def test_numpy_rounding_equals_pythons_round_on_device_values() -> None:
    """The claim behind rounding with numpy: same as round() for q6 angles, q2 distances."""
    assert np.round(Q6_ANGLES, 2).tolist() == [round(a, 2) for a in Q6_ANGLES.tolist()]
    q2 = np.arange(0, 16001 * 4) / 4.0
    assert np.round(q2, 1).tolist() == [round(d, 1) for d in q2.tolist()]


def test_ld_ranges_follow_the_vendor_driver() -> None:
    """(0, 0) is NaN; 0 with an intensity is 0.0; nothing is range-filtered; empty is NaN."""
    angles = np.array([0.0, 0.8, 1.6, 2.4])
    distances = np.array([0, 0, 30000, 10])
    intensities = np.array([0, 100, 200, 200])
    out = ld_ranges(angles, distances, intensities, 450)
    assert math.isnan(out[0]) and out[449] == 0.0
    assert (out[448], out[447]) == (30.0, 0.01)
    assert np.isnan(out[1:447]).all()
