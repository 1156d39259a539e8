"""Fault profiles: pipeline order, encodings, rates, determinism, config errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from harness.errors import ConfigError
from harness.faults.sensor import (
    CONVENTIONS,
    NAMED_PROFILES,
    RETURN_INTENSITY,
    Convention,
    Dropouts,
    FarReturns,
    FaultProfile,
    Noise,
    Spurious,
    build_profile,
)
from harness.lidar.spec import PRESETS, LidarSpec

GAZEBO = PRESETS["gazebo"]
BIG = LidarSpec("big", 10000, 0.0, 2 * math.pi / 10000, 0.12, 12.0, 10.0)


def truth_for(spec: LidarSpec) -> np.ndarray:
    """A third valid hits, a third too close, a third no return."""
    t = np.full(spec.samples, np.inf)
    n = spec.samples // 3
    t[:n] = np.linspace(0.5, 5.0, n)
    t[n : 2 * n] = spec.range_min / 2
    return t


def emit(profile: FaultProfile, truth: np.ndarray, spec: LidarSpec = GAZEBO, seed: int = 0):
    return profile.emit(truth, spec, np.random.default_rng(seed), stamp=1.5)


def test_clean_is_rep117_and_exact() -> None:
    """No faults: hits exact in float32, no return +inf, too close -inf."""
    t = truth_for(GAZEBO)
    scan = emit(FaultProfile(), t)
    n = GAZEBO.samples // 3
    assert scan.ranges.dtype == np.float32
    assert np.array_equal(scan.ranges[:n], t[:n].astype(np.float32))
    assert np.all(scan.ranges[n : 2 * n] == -np.inf)
    assert np.all(scan.ranges[2 * n :] == np.inf)
    assert np.array_equal(scan.valid_mask(), np.arange(GAZEBO.samples) < n)


def test_scan_fields_come_from_spec() -> None:
    """The emitted LaserScan header fields are the spec's, plus the stamp."""
    scan = emit(FaultProfile(), truth_for(GAZEBO))
    assert scan.angle_min == GAZEBO.angle_min
    assert scan.angle_max == GAZEBO.angle_max
    assert scan.angle_increment == GAZEBO.angle_increment
    assert scan.time_increment == GAZEBO.time_increment
    assert scan.scan_time == GAZEBO.scan_time
    assert (scan.range_min, scan.range_max) == (GAZEBO.range_min, GAZEBO.range_max)
    assert scan.stamp == 1.5
    assert scan.ranges.size == scan.intensities.size == GAZEBO.samples


def test_intensity_marks_returns() -> None:
    """Valid returns and ghosts carry RETURN_INTENSITY, everything else 0."""
    t = truth_for(GAZEBO)
    scan = emit(FaultProfile(), t)
    assert np.array_equal(scan.intensities > 0, scan.valid_mask())
    assert set(np.unique(scan.intensities)) == {0.0, RETURN_INTENSITY}


@pytest.mark.parametrize("name", sorted(NAMED_PROFILES))
def test_same_seed_byte_identical(name: str) -> None:
    """Same profile + seed + truth gives the same bytes; every named profile."""
    profile = build_profile([name])
    t = truth_for(GAZEBO)
    assert emit(profile, t, seed=7).to_bytes() == emit(profile, t, seed=7).to_bytes()


def test_different_seed_differs() -> None:
    """The seed matters for random faults."""
    profile = build_profile(["harsh"])
    t = truth_for(GAZEBO)
    assert emit(profile, t, seed=1).to_bytes() != emit(profile, t, seed=2).to_bytes()


def test_random_stream_independent_of_truth() -> None:
    """Draws have a fixed size, so the generator advances the same whatever is seen."""
    profile = build_profile(["harsh"])
    a, b = np.random.default_rng(3), np.random.default_rng(3)
    profile.emit(truth_for(GAZEBO), GAZEBO, a, stamp=0)
    profile.emit(np.full(GAZEBO.samples, np.inf), GAZEBO, b, stamp=0)
    assert a.random() == b.random()


def test_noise_statistics_and_scope() -> None:
    """Noise has the asked sigma on hits and leaves no-return beams alone."""
    t = np.full(BIG.samples, np.inf)
    t[: BIG.samples // 2] = 3.0
    scan = emit(FaultProfile((Noise(0.02),)), t, BIG)
    hits = scan.ranges[: BIG.samples // 2].astype(np.float64) - 3.0
    assert abs(hits.std() - 0.02) < 0.002
    assert abs(hits.mean()) < 0.002
    assert np.all(scan.ranges[BIG.samples // 2 :] == np.inf)
    assert FaultProfile((Noise(0.02),)).noise_sigma == 0.02
    assert FaultProfile().noise_sigma == 0.0


def test_noise_is_classified_after() -> None:
    """Noise that pushes a hit past range_max or below range_min is encoded, not emitted raw."""
    t = np.full(BIG.samples, BIG.range_max - 0.001)
    t[::2] = BIG.range_min + 0.001
    scan = emit(FaultProfile((Noise(0.05),)), t, BIG)
    r = scan.ranges
    assert np.all(np.isin(r[~scan.valid_mask()], [np.inf, -np.inf]))
    assert np.sum(r == np.inf) > 1000 and np.sum(r == -np.inf) > 1000


@pytest.mark.parametrize(
    "value, check", [("nan", np.isnan), ("zero", lambda r: r == 0.0), ("inf", np.isposinf)]
)
def test_dropout_rate_and_value(value: str, check) -> None:
    """About `rate` of the valid returns read the dropout value; others untouched."""
    t = np.full(BIG.samples, 2.0)
    t[-1000:] = np.inf  # no-return beams are never "dropped"
    scan = emit(FaultProfile((Dropouts(0.1, value),)), t, BIG, seed=11)
    dropped = check(scan.ranges[:-1000])
    assert 0.08 < dropped.mean() < 0.12
    assert np.all(scan.ranges[:-1000][~dropped] == np.float32(2.0))
    assert np.all(scan.ranges[-1000:] == np.inf)


def test_dropouts_ignore_convention() -> None:
    """A dropout value is literal; the driver convention encodes only no-return/too-close."""
    t = np.full(BIG.samples, 2.0)
    t[:100] = np.inf
    profile = FaultProfile((Dropouts(0.5, "nan"),), convention="zero")
    r = emit(profile, t, BIG).ranges
    assert np.all(r[:100] == 0.0)
    assert np.isnan(r[100:]).any() and not (r[100:] == 0).any()


def test_spurious_rate_and_values() -> None:
    """Ghosts hit about `rate` of all beams, strictly inside (0, range_min), invalid."""
    t = np.full(BIG.samples, np.inf)
    t[:5000] = 1.0
    scan = emit(FaultProfile((Spurious(0.05),)), t, BIG, seed=5)
    r = scan.ranges
    ghost = np.isfinite(r) & (r < np.float32(BIG.range_min))
    assert 0.04 < ghost.mean() < 0.06
    assert np.all((r[ghost] > 0) & (r[ghost] < np.float32(BIG.range_min)))
    assert not scan.valid_mask()[ghost].any()
    assert np.all(scan.intensities[ghost] == RETURN_INTENSITY)


def test_far_returns_only_on_no_return_beams_beyond_range_max() -> None:
    """Raw distances past range_max replace about `rate` of the no-return beams only, stay
    within [1.02, 1.25) * range_max, invalid, and are not re-encoded by the convention."""
    t = np.full(BIG.samples, np.inf)
    t[:5000] = 1.0
    scan = emit(FaultProfile((FarReturns(0.1),), convention="nan"), t, BIG, seed=5)
    r = scan.ranges
    far = np.isfinite(r) & (r > np.float32(BIG.range_max))
    assert not far[:5000].any()  # valid returns are left alone
    assert 0.08 < far[5000:].mean() < 0.12
    top = np.float32(1.25 * BIG.range_max)
    assert np.all((r[far] >= np.float32(1.02 * BIG.range_max)) & (r[far] <= top))
    assert not scan.valid_mask()[far].any()
    assert np.isnan(r[5000:][~far[5000:]]).all()  # the other no-return beams: NaN convention
    again = emit(FaultProfile((FarReturns(0.1),), convention="nan"), t, BIG, seed=5)
    assert again.to_bytes() == scan.to_bytes()


@pytest.mark.parametrize(
    "convention, no_return, too_close",
    [
        ("rep117", np.inf, -np.inf),
        ("inf", np.inf, np.inf),
        ("range_max", np.float32(12.0), -np.inf),
        ("nan", np.nan, np.nan),
        ("zero", 0.0, 0.0),
    ],
)
def test_conventions(convention: str, no_return: float, too_close: float) -> None:
    """Each driver convention writes no-return and too-close its own way."""
    t = truth_for(GAZEBO)
    scan = emit(FaultProfile(convention=convention), t)
    n = GAZEBO.samples // 3
    np.testing.assert_array_equal(scan.ranges[n : 2 * n], np.float32(too_close))
    np.testing.assert_array_equal(scan.ranges[2 * n :], np.float32(no_return))
    assert np.array_equal(scan.ranges[:n], t[:n].astype(np.float32))


def test_conventions_table_complete() -> None:
    """Every convention has a driver profile or is the default."""
    used = {p.convention for _, p in NAMED_PROFILES.values()}
    assert used == set(CONVENTIONS)


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(
        st.one_of(st.floats(0.0, 14.0), st.just(math.inf), st.floats(0.1199, 0.1201)),
        min_size=360,
        max_size=360,
    ),
    sigma=st.sampled_from([0.0, 0.01, 0.5]),
    seed=st.integers(0, 2**32 - 1),
)
def test_rep117_invariant(values: list[float], sigma: float, seed: int) -> None:
    """REP-117 with noise only: every beam is valid, +inf or -inf; validity agrees with float32."""
    scan = emit(FaultProfile((Noise(sigma),)), np.array(values), GAZEBO, seed)
    r = scan.ranges
    valid = scan.valid_mask()
    assert np.all(np.isin(r[~valid], [np.inf, -np.inf]))
    assert np.all(np.isfinite(r) == valid)


def test_truth_shape_checked() -> None:
    """A truth array of the wrong length is a harness bug, not a config error."""
    with pytest.raises(ValueError, match="360 beams"):
        emit(FaultProfile(), np.ones(10))


# -- build_profile ---------------------------------------------------------


def test_named_profiles_have_descriptions() -> None:
    """Every named profile builds and describes itself."""
    for name, (description, profile) in NAMED_PROFILES.items():
        assert description and profile.name == name
        assert build_profile([name]) == profile
        assert profile.describe().startswith(name)


def test_empty_list_is_clean() -> None:
    """No faults listed: clean REP-117."""
    assert build_profile([]) == FaultProfile(name="clean")


def test_compose_and_override() -> None:
    """Later items replace earlier ones of the same kind; others compose."""
    p = build_profile(["driver_nan", "noisy", {"type": "noise", "sigma": 0.03}, "dropouts_zero"])
    assert p.convention == "nan"
    assert p.faults == (Noise(0.03), Dropouts(0.05, "zero"))
    assert p.name == "driver_nan+noisy+noise(sigma=0.03)+dropouts_zero"
    q = build_profile(
        ["harsh", {"type": "convention", "name": "rep117"}, {"type": "spurious", "rate": 0}]
    )
    assert q.convention == "rep117" and Spurious(0.0) in q.faults


def test_fault_order_is_canonical() -> None:
    """Profiles list faults in pipeline order whatever the input order."""
    a = FaultProfile((Spurious(0.1), Noise(0.01)))
    assert a.faults == (Noise(0.01), Spurious(0.1))


@pytest.mark.parametrize(
    "items, message",
    [
        (["nosie"], r"faults\[0\]: unknown fault profile 'nosie' \(known: clean, "),
        (
            ["clean", {"type": "nosie"}],
            r"faults\[1\]: unknown fault type 'nosie' "
            r"\(known: convention, delay, drop, dropouts, duplicate, far_returns, "
            r"line_corruption, line_drops, line_noise, noise, rate_drift, reorder, spurious, "
            r"stale_stamps\)",
        ),
        ([{"sigma": 0.1}], r"faults\[0\]: missing 'type'"),
        ([{"type": "dropouts", "rate": 1.5}], r"faults\[0\]\.rate: must be in \[0, 1\]"),
        ([{"type": "dropouts", "rate": -0.1}], r"faults\[0\]\.rate: must be in \[0, 1\]"),
        ([{"type": "spurious", "rate": True}], r"faults\[0\]\.rate: must be a number"),
        ([{"type": "noise", "sigma": "big"}], r"faults\[0\]\.sigma: must be a number"),
        ([{"type": "noise", "sigma": float("nan")}], r"faults\[0\]\.sigma: must be in"),
        ([{"type": "noise"}], r"faults\[0\]\.sigma: required for noise"),
        (
            [{"type": "noise", "sigma": 0.1, "seed": 3}],
            r"faults\[0\]: unknown key 'seed' for noise \(known: sigma\)",
        ),
        (
            [{"type": "dropouts", "rate": 0.1, "value": "neg"}],
            r"faults\[0\]: dropouts value must be one of nan, zero, inf",
        ),
        ([{"type": "convention", "name": "ros"}], r"faults\[0\]: unknown driver convention 'ros'"),
        ([3], r"faults\[0\]: expected a profile name or a mapping"),
        ("noisy", r"faults: must be a list"),
    ],
)
def test_config_errors(items, message: str) -> None:
    """Each mistake names the item and field."""
    with pytest.raises(ConfigError, match=message):
        build_profile(items)


def test_direct_construction_checks() -> None:
    """Fault dataclasses refuse nonsense too."""
    with pytest.raises(ConfigError):
        Noise(-1.0)
    with pytest.raises(ConfigError):
        Convention("ros")
    with pytest.raises(ConfigError, match="one fault of each kind"):
        FaultProfile((Noise(0.1), Noise(0.2)))
