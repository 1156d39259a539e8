"""Oracle: expectations from the emitted scan, tolerances, and what verdicts say."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from gazebo_scans import INC, N, make_scan

from harness.errors import ConfigError
from harness.faults.sensor import NAMED_PROFILES
from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle, summarise_scan
from harness.lidar.scan import Scan
from harness.lidar.spec import PRESETS


def angle(scan: Scan, i: int) -> float:
    return scan.angle_min + i * scan.angle_increment


def ans(*statuses: str, warnings: tuple[bool, ...] = (), **kw) -> Answers:
    return Answers(
        statuses=[Received(s, 0.01) for s in statuses],
        warnings=[Received(w, 0.01) for w in warnings],
        waited=0.01,
        **kw,
    )


def judge(scan: Scan, answers: Answers, threshold: float = 0.5, **kw):
    return Oracle(threshold, **kw).judge(32, 3.2, scan, answers)


def good(scan: Scan, i: int, decimals: int = 3) -> str:
    d = float(scan.ranges[i])
    return f"Obstacle at {d:.{decimals}f} m, angle {angle(scan, i):.{decimals}f} rad"


# -- expectations -------------------------------------------------------------


def test_no_valid_return_means_no_obstacle() -> None:
    """All +inf: no obstacle, no warning."""
    exp = Oracle(0.5).expect(make_scan())
    assert (exp.obstacle, exp.distance, exp.angle, exp.index, exp.warning) == (
        False,
        None,
        None,
        None,
        False,
    )


def test_invalid_readings_ignored() -> None:
    """-inf, NaN, 0, below range_min, above range_max and negatives never count."""
    scan = make_scan(
        {0: -math.inf, 1: math.nan, 2: 0.0, 3: 0.05, 4: 12.5, 5: -1.0, 6: 0.11999, 200: 2.0}
    )
    exp = Oracle(0.5).expect(scan)
    assert (exp.obstacle, exp.distance, exp.index) == (True, 2.0, 200)
    assert exp.angle == pytest.approx(angle(scan, 200))
    assert exp.warning is False
    assert judge(scan, ans(good(scan, 200))).ok


def test_range_min_and_max_inclusive() -> None:
    """Readings exactly at range_min are valid (REP-117 bounds are inclusive)."""
    scan = make_scan({10: 0.12})
    exp = Oracle(0.5).expect(scan)
    assert exp.distance == pytest.approx(0.12) and exp.index == 10 and exp.warning is True


def test_ties_any_beam_is_right() -> None:
    """Several beams at exactly the minimum: any of their angles passes."""
    scan = make_scan({40: 1.0, 200: 1.0, 300: 1.5})
    exp = Oracle(0.5).expect(scan)
    assert exp.indices == (40, 200) and exp.index == 40
    assert judge(scan, ans(good(scan, 40))).ok
    assert judge(scan, ans(good(scan, 200))).ok
    bad = judge(scan, ans(f"Obstacle at 1.0 m, angle {angle(scan, 120):.3f}"))
    assert not bad.ok and "(beam 40; also beam 200)" in bad.explanation
    assert "give or take 0.0" in bad.explanation and "-pi..pi and 0..2pi both" in bad.explanation
    three = make_scan({40: 1.0, 200: 1.0, 300: 1.0})
    worse = judge(three, ans(f"Obstacle at 1.0 m, angle {angle(three, 120):.3f}"))
    assert "(beam 40; also beams 200, 300)" in worse.explanation


# -- range_max convention -------------------------------------------------------


def test_range_max_only_accepts_either() -> None:
    """Only readings at range_max (the range_max convention): clear or range_max both pass."""
    scan = make_scan(fill=12.0)
    exp = Oracle(0.5).expect(scan)
    assert exp.obstacle and exp.may_be_clear and len(exp.indices) == N
    assert judge(scan, ans("No obstacle")).ok
    assert judge(scan, ans("Obstacle at 12.0 m, angle 1.0 rad")).ok
    wrong = judge(scan, ans("Obstacle at 5.0 m, angle 1.0 rad"))
    assert not wrong.ok and "= range_max" in wrong.explanation


def test_range_max_with_real_obstacle() -> None:
    """A real return below range_max is the minimum as usual; 'no obstacle' fails."""
    scan = make_scan({100: 3.0}, fill=12.0)
    assert not Oracle(0.5).expect(scan).may_be_clear
    assert judge(scan, ans(good(scan, 100))).ok
    assert not judge(scan, ans("No obstacle")).ok


# -- warnings and the threshold band --------------------------------------------


@pytest.mark.parametrize(
    "d, expected",
    [(0.40, True), (0.494, True), (0.496, None), (0.5, None), (0.504, None), (0.506, False)],
)
def test_threshold_band(d: float, expected: bool | None) -> None:
    """Default band 5 mm either side of the threshold: either answer accepted there."""
    exp = Oracle(0.5).expect(make_scan({90: d}))
    assert exp.warning is expected


def test_band_from_noise_and_explicit() -> None:
    """The band grows with noise (3 sigma) and can be set; band 0 is the strict rule."""
    assert Oracle(0.5, noise_sigma=0.01).band == pytest.approx(0.03)
    assert Oracle(0.5).band == 0.005
    strict = Oracle(0.5, band=0.0)
    assert strict.expect(make_scan({90: 0.5})).warning is False  # not < threshold
    assert strict.expect(make_scan({90: 0.4999})).warning is True


def test_in_band_either_warning_ok() -> None:
    """Inside the band True, False and nothing all pass."""
    scan = make_scan({90: 0.5})
    for w in ((True,), (False,), ()):
        assert judge(scan, ans(good(scan, 90), warnings=w)).ok


def test_warning_true_required() -> None:
    """Under the threshold a True is required; none or False fails with both sides named."""
    scan = make_scan({90: 0.41})
    assert judge(scan, ans(good(scan, 90), warnings=(True,))).ok
    missing = judge(scan, ans(good(scan, 90)))
    assert missing.failures == ("expected warning True; got no Bool",)
    assert re.fullmatch(
        r"t=3\.20 s tick 32: nearest valid return 0\.41 m at -1\.566 rad \(beam 90\); "
        r"threshold 0\.50 m; expected warning True; got no Bool",
        missing.explanation,
    )
    false = judge(scan, ans(good(scan, 90), warnings=(False,)))
    assert false.failures == ("expected warning True; got False",) and false.warning_got is False


def test_last_bool_counts() -> None:
    """Several Bools for one scan: the last one is the answer."""
    scan = make_scan({90: 0.41})
    assert judge(scan, ans(good(scan, 90), warnings=(False, True))).ok
    assert not judge(scan, ans(good(scan, 90), warnings=(True, False))).ok


def test_warning_when_clear() -> None:
    """Clear: True fails; False or nothing pass (unless a Bool is required)."""
    scan = make_scan({90: 3.0})
    assert judge(scan, ans(good(scan, 90))).ok
    assert judge(scan, ans(good(scan, 90), warnings=(False,))).ok
    true = judge(scan, ans(good(scan, 90), warnings=(True,)))
    assert true.failures == ("expected warning False (or none); got True",)
    strict = judge(scan, ans(good(scan, 90)), warning_required_when_clear=True)
    assert strict.failures == ("expected warning False; got no Bool",)
    empty = make_scan()
    assert not judge(empty, ans("No obstacle", warnings=(True,))).ok


# -- distance -------------------------------------------------------------------


def test_distance_printed_precision() -> None:
    """Tolerance is half a unit in the last printed digit (plus float32 rounding)."""
    scan = make_scan({90: 0.4123})
    a = f"{angle(scan, 90):.3f}"
    w = (True,)
    assert judge(scan, ans(f"Obstacle at 0.41 m, {a}", warnings=w)).ok
    assert judge(scan, ans(f"Obstacle at 0.4123 m, {a}", warnings=w)).ok
    assert judge(scan, ans(f"Obstacle at {float(scan.ranges[90])!r} m, {a}", warnings=w)).ok
    assert judge(scan, ans(f"Obstacle at {scan.ranges[90]} m, {a}", warnings=w)).ok  # float32
    off = judge(scan, ans(f"Obstacle at 0.42 m, {a}", warnings=w))
    assert len(off.failures) == 1 and "expected distance 0.4123 m" in off.failures[0]
    assert "gives 0.42 m" in off.failures[0]
    assert not judge(scan, ans(f"Obstacle at 0.413 m, {a}", warnings=w)).ok


def test_raw_min_including_invalid_caught() -> None:
    """A node taking min() over invalid readings is wrong, and told which beam it took."""
    scan = make_scan({5: 0.05, 90: 1.0})
    v = judge(scan, ans(f"Obstacle at 0.05 m, {angle(scan, 5):.3f}"))
    assert not v.ok and "beam 5's invalid reading, below range_min" in v.explanation


def test_centimetres_hint() -> None:
    """Distances in centimetres fail with a hint."""
    scan = make_scan({90: 0.84})
    v = judge(scan, ans(f"Obstacle at 84 cm, {angle(scan, 90):.3f} rad"))
    assert not v.ok and "(looks like centimetres)" in v.explanation


# -- angle ----------------------------------------------------------------------


def test_angle_one_increment_ok_two_not() -> None:
    """The angle may be one beam off (printed to 4 decimals), not two."""
    scan = make_scan({100: 1.0})
    for off, ok in ((-1, True), (1, True), (0, True), (2, False), (-2, False)):
        text = f"Obstacle at 1.0 m, angle {angle(scan, 100) + off * INC:.4f}"
        assert judge(scan, ans(text)).ok is ok, off


def test_angle_printed_precision() -> None:
    """A coarsely printed angle gets half a printed unit on top of one beam."""
    scan = make_scan({100: 1.0})  # -1.3914 rad; one beam is 0.0175
    assert judge(scan, ans("Obstacle at 1.0 m, angle -1.4")).ok  # tol 0.05 + 0.0175
    assert not judge(scan, ans("Obstacle at 1.0 m, angle -1.42")).ok  # tol 0.005 + 0.0175


@pytest.mark.parametrize("preset", ["gazebo", "rplidar_a1"])
def test_other_wrap_accepted(preset: str) -> None:
    """A correct angle in another standard wrap passes; beyond [-2pi, 2pi] it does not."""
    spec = PRESETS[preset]
    kw = dict(
        angle_min=spec.angle_min,
        angle_max=spec.angle_max,
        angle_increment=spec.angle_increment,
    )
    for i in (10, 90, 170, 200, 290, 350):
        scan = make_scan({i: 1.0}, **kw)
        a = angle(scan, i)
        other = a - 2 * math.pi if a > 0 else a + 2 * math.pi
        assert judge(scan, ans(f"Obstacle at 1.0 m, angle {a:.4f}")).ok
        assert judge(scan, ans(f"Obstacle at 1.0 m, angle {other:.4f}")).ok, (i, other)
        far = a + 4 * math.pi if a > 0 else a - 4 * math.pi
        v = judge(scan, ans(f"Obstacle at 1.0 m, angle {far:.4f}"))
        assert not v.ok and "outside [-2*pi, 2*pi]" in v.explanation


@pytest.mark.parametrize("decimals", [0, 1, 2])
def test_degrees_always_caught(decimals: int) -> None:
    """Angles in degrees fail on every beam not within a hair of 0 rad."""
    passed = []
    for i in range(N):
        scan = make_scan({i: 1.0})
        a = angle(scan, i)
        if abs(a) < 0.03:
            continue
        v = judge(scan, ans(f"Obstacle at 1.0 m, angle {math.degrees(a):.{decimals}f}"))
        if v.ok:
            passed.append(i)
        else:
            assert "looks like degrees" in v.explanation
    assert passed == []


def test_index_instead_of_angle_hint() -> None:
    """Printing the beam index instead of the angle is named."""
    scan = make_scan({100: 1.0})
    v = judge(scan, ans("Obstacle at 1.0 m, angle 100"))
    assert "looks like the beam index" in v.explanation


def test_missing_angle() -> None:
    """No angle fails unless the oracle is told angles are not required (lab step 1)."""
    scan = make_scan({100: 1.0})
    v = judge(scan, ans("Obstacle at 1.0 m"))
    assert v.failures == ("status 'Obstacle at 1.0 m' gives no angle (expected -1.391 rad)",)
    assert judge(scan, ans("Obstacle at 1.0 m"), require_angle=False).ok


# -- status claims ----------------------------------------------------------------


def test_inf_status_when_clear() -> None:
    """The lab's pitfall: 'Min distance: inf' when nothing is in range is an obstacle claim."""
    v = judge(make_scan(), ans("Min distance: inf"))
    assert v.explanation == (
        "t=3.20 s tick 32: expected no obstacle (no valid return: 360 +inf); "
        "threshold 0.50 m; status 'Min distance: inf' claims an obstacle at inf m"
    )
    assert v.claim is not None and v.claim.distance == math.inf


@pytest.mark.parametrize("text", ["Min distance: inf", "Min distance: nan"])
def test_non_finite_status_with_obstacle(text: str) -> None:
    """inf or nan while a valid return exists is a wrong distance."""
    scan = make_scan({90: 1.0})
    v = judge(scan, ans(text))
    assert not v.ok and "a non-finite distance while a valid return exists" in v.explanation


def test_no_obstacle_claimed_with_obstacle() -> None:
    """'No obstacle' with a valid return names the phrase that decided it."""
    scan = make_scan({90: 3.0})
    v = judge(scan, ans("No obstacle"))
    assert v.failures == (
        "expected an obstacle at 3.00 m; status 'No obstacle' claims none (says 'No obstacle')",
    )


def test_clear_statuses_pass() -> None:
    """Any 'no obstacle' wording passes on a scan with no valid return."""
    scan = make_scan({1: -math.inf, 2: math.nan, 3: 0.0, 4: 0.05})
    for text in ("No obstacle", "nothing detected", "All clear", "Obstacle: False"):
        assert judge(scan, ans(text)).ok, text
    v = judge(scan, ans("Min distance: 0.05"))
    assert "no valid return: 356 +inf, 1 -inf, 1 NaN, 1 zero, 1 below range_min" in v.explanation


def test_user_status_pattern() -> None:
    """The oracle parses statuses with the user's regex when given one."""
    scan = make_scan({100: 1.0})
    text = f"{angle(scan, 100):.3f} | 1.000"
    o = Oracle(0.5, status_pattern=r"(?P<angle>\S+) \| (?P<distance>\S+)")
    assert o.judge(0, 0.0, scan, ans(text)).ok
    assert not judge(scan, ans(text)).ok  # default rules read A first: wrong


# -- how answers arrived ------------------------------------------------------------


def test_no_status_within_deadline() -> None:
    """Nothing arrived before the deadline: fail, saying how long we waited."""
    v = judge(make_scan(), Answers(waited=1.0, timed_out=True))
    assert v.failures == ("no status within the deadline (1.00 s)",) and v.claim is None


def test_duplicate_status() -> None:
    """Two statuses for one scan fail even when both are right."""
    v = judge(make_scan(), ans("No obstacle", "No obstacle"))
    assert len(v.failures) == 1
    assert v.failures[0].startswith("answered twice (one status per scan expected): 'No obstacle'")


def test_link_problem_reported() -> None:
    """A link-level problem fails the tick with its text."""
    v = judge(make_scan(), ans(problem="node exited with code 1: Traceback"))
    assert "link problem: node exited with code 1: Traceback" in v.failures
    assert "no status arrived" in v.failures


def test_failures_accumulate() -> None:
    """One verdict names every problem: status and warning."""
    scan = make_scan({90: 0.3})
    v = judge(scan, ans("No obstacle", warnings=(False,)))
    assert len(v.failures) == 2 and v.explanation.count(";") >= 3


def test_ok_verdict_is_quiet() -> None:
    """A right answer has no failures and an empty explanation."""
    scan = make_scan({90: 0.3})
    v = judge(scan, ans(good(scan, 90), warnings=(True,)))
    assert v.ok and v.failures == () and v.explanation == "" and v.warning_got is True
    assert (v.tick, v.t) == (32, 3.2)


def test_config_errors() -> None:
    """Nonsense oracle settings are the user's to fix."""
    with pytest.raises(ConfigError, match="threshold"):
        Oracle(0.0)
    with pytest.raises(ConfigError, match="band"):
        Oracle(0.5, band=-1)
    with pytest.raises(ConfigError, match="bad regex"):
        Oracle(0.5, status_pattern="(?P<distance>")


def test_summarise_scan() -> None:
    """Counts by kind, zero counts omitted."""
    scan = make_scan({0: math.nan, 1: math.nan, 2: 1.0, 3: 12.0, 4: 13.0})
    assert summarise_scan(scan) == "2 valid (1 at range_max), 355 +inf, 2 NaN, 1 above range_max"


# -- against a slow obvious reference, through the fault pipeline --------------------


def reference_status(ranges: list[float], a_min: float, inc: float, lo: float, hi: float) -> str:
    """A correct student node, written the plain way."""
    best, best_i = None, None
    for i, r in enumerate(ranges):
        if math.isfinite(r) and lo <= r <= hi and (best is None or r < best):
            best, best_i = r, i
    if best is None:
        return "No obstacle"
    return f"Obstacle at {best:.3f} m, angle {a_min + best_i * inc:.3f} rad"


@pytest.mark.parametrize("profile", sorted(NAMED_PROFILES))
def test_reference_node_passes_every_profile(profile: str) -> None:
    """A plain correct node passes on every named profile, for many seeds and distances."""
    spec = PRESETS["rplidar_a1"]
    prof = NAMED_PROFILES[profile][1]
    rng = np.random.default_rng(1)
    oracle = Oracle(0.5, noise_sigma=prof.noise_sigma)
    for tick in range(40):
        truth = np.full(spec.samples, np.inf)
        if tick % 4:
            lo = rng.uniform(0.0, 3.0)
            truth[rng.integers(0, spec.samples, 30)] = rng.uniform(lo, lo + 2.0, 30)
        scan = prof.emit(truth, spec, rng, stamp=tick * 0.1)
        # float32 -> float compare, as rclpy hands the node an array('f')
        lo32, hi32 = float(np.float32(scan.range_min)), float(np.float32(scan.range_max))
        text = reference_status(
            [float(x) for x in scan.ranges], scan.angle_min, scan.angle_increment, lo32, hi32
        )
        exp = oracle.expect(scan)
        warn = (True,) if exp.distance is not None and exp.distance < 0.5 else ()
        v = oracle.judge(tick, tick * 0.1, scan, ans(text, warnings=warn))
        assert v.ok, v.explanation


def test_a_huge_claimed_distance_is_judged_without_numeric_warnings() -> None:
    """A claim beyond float32 (1e300 m) is simply wrong: no overflow on the way."""
    import warnings

    from harness.judge.oracle import _distance_hint

    scan = Scan(0.0, 1.0, 0.5, 0.0, 0.1, 0.12, 12.0, np.array([0.05, 1.0, 20.0], np.float32))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _distance_hint(scan, 1.0, 1e300, 0.05) == ""
        assert "below range_min" in _distance_hint(scan, 1.0, 0.05, 0.01)
