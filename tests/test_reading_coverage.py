"""Reading coverage: which kinds of readings the delivered scans carry (pure)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from gazebo_scans import N, make_scan

from harness.faults.link import Delivery
from harness.judge.answers import Answers
from harness.judge.oracle import Oracle
from harness.judge.reading_coverage import (
    CASES,
    ReadingCoverage,
    _features,
    coverage_by_scenario,
    coverage_of,
    gaps,
)
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan

VALUE = {
    "nan": math.nan,
    "pos_inf": math.inf,
    "neg_inf": -math.inf,
    "zero": 0.0,
    "below_range_min": 0.05,
    "above_range_max": 12.5,
}


def run_of(
    scans: list[Scan],
    threshold: float = 0.5,
    *,
    name: str = "hand_made",
    noise_sigma: float = 0.0,
    deliveries: list[Delivery] | None = None,
    lost: frozenset[int] = frozenset(),
) -> RunResult:
    """A run that delivered `scans` in order, judged by its oracle (no answers)."""
    oracle = Oracle(threshold, noise_sigma=noise_sigma)
    result = RunResult(name, "inprocess", 0, threshold, "clean", noise_sigma)
    for k, scan in enumerate(scans):
        delivery = deliveries[k] if deliveries else Delivery()
        answers = Answers(lost="damaged on the line" if k in lost else None)
        verdict = oracle.judge(k, k * 0.1, scan, answers, delivery)
        result.records.append(
            TickRecord(k, k * 0.1, 0.0, 0.0, 0.0, scan, answers, verdict, delivery)
        )
    return result


def at(distance: float, beam: int = 180, **kw) -> Scan:
    """Nothing but one return at `distance` on `beam`."""
    return make_scan({beam: distance}, **kw)


def cases_hit(c: ReadingCoverage) -> dict[str, tuple[int, int]]:
    return {k: (c.beside_valid[k], c.without_valid[k]) for k in CASES if k in c.beside_valid}


# -- the REP-117 cases --------------------------------------------------------


@pytest.mark.parametrize("case", CASES)
def test_each_case_beside_and_without_a_valid_return(case: str) -> None:
    """A scan full of one case counts as 'without'; with one valid return, as 'beside'."""
    fill = VALUE[case]
    without = make_scan(fill=fill)
    beside = make_scan({100: 2.0}, fill=fill)
    c = coverage_of([run_of([without, beside, beside])])
    assert c.scans == 3
    got = {k: v for k, v in cases_hit(c).items() if v != (0, 0)}
    assert got == {case: (2, 1)}


def test_readings_at_the_limits_are_valid_not_a_case() -> None:
    """range_min and range_max themselves (as float32) are valid: no case, a valid return."""
    scan = make_scan({10: 0.12, 20: 12.0}, fill=3.0)
    c = ReadingCoverage().add([scan], 0.5, 0.005)
    assert all(v == (0, 0) for v in cases_hit(c).values())
    assert c.near_threshold == 0  # the nearest is 0.12 m, far below 0.5 - 0.105


def test_zero_is_valid_when_range_min_is_zero() -> None:
    """With range_min 0, a 0.0 reading is a return (and the nearest), not the zero case."""
    c = ReadingCoverage().add([make_scan({5: 0.0}, range_min=0.0)], 0.5, 0.005)
    assert c.beside_valid["zero"] == c.without_valid["zero"] == 0
    assert c.beside_valid["pos_inf"] == 1


def test_negative_readings_are_no_listed_case() -> None:
    """A finite negative reading is invalid, but none of the six cases."""
    c = ReadingCoverage().add([make_scan({5: -1.0}, fill=math.nan)], 0.5, 0.005)
    assert cases_hit(c)["nan"] == (0, 1)
    assert sum(a + b for a, b in cases_hit(c).values()) == 1


def test_nearest_return_agrees_with_the_oracle() -> None:
    """Random scans with every case mixed in: the same nearest return and angle as the oracle."""
    rng = np.random.default_rng(7)
    invalid = np.array([math.nan, math.inf, -math.inf, 0.0, 0.05, 12.5, -1.0])
    limits = np.array([0.12, 12.0])  # valid, exactly at range_min and range_max
    oracle = Oracle(0.5)
    for k in range(200):
        r = rng.uniform(0.38, 13.0, N)  # the nearest often near the threshold
        pick = rng.random(N) < 0.5
        r[pick] = rng.choice(invalid, int(pick.sum()))
        if k % 4 == 0:
            r[rng.integers(0, N, 3)] = rng.choice(limits, 3)
        if k % 5 == 0:
            r[:] = rng.choice(invalid, N)  # nothing valid at all
        scan = make_scan(dict(enumerate(r)))
        exp = oracle.expect(scan)
        f = _features([scan])
        assert bool(f.has_valid[0]) == exp.obstacle
        if exp.obstacle:
            assert (f.distance[0], f.angle[0]) == (exp.distance, exp.angle)
        c = ReadingCoverage().add([scan], 0.5, oracle.band)
        near = exp.distance is not None and exp.warning is not None
        near = near and abs(exp.distance - 0.5) <= oracle.band + 0.1
        assert c.near_threshold == int(near)


# -- angles -------------------------------------------------------------------


def test_angle_min_zero_and_minus_pi() -> None:
    """angle_min 0 and -pi counted (within 1e-6); a third layout neither."""
    scans = [
        at(1.0, angle_min=0.0, angle_max=2 * math.pi),
        at(1.0, angle_min=-math.pi + 5e-7),
        at(1.0, angle_min=-math.pi / 2, angle_max=3 * math.pi / 2),
    ]
    c = ReadingCoverage().add(scans, 0.5, 0.005)
    assert (c.angle_min_zero, c.angle_min_minus_pi) == (1, 1)


@pytest.mark.parametrize(
    ("angle_min", "beam", "near"),
    [
        (-math.pi, 0, True),  # -pi
        (-math.pi, N - 1, True),  # +pi
        (-math.pi, 5, True),  # -pi + 0.088
        (-math.pi, 12, False),  # -pi + 0.21
        (-math.pi, 180, False),  # 0
        (0.0, 180, True),  # pi, in a 0..2pi scan
        (0.0, N - 1, False),  # 2pi: straight ahead again
        (0.0, 0, False),
    ],
)
def test_angle_near_pi_wherever_the_scan_starts(angle_min: float, beam: int, near: bool) -> None:
    """Within 0.2 rad of +-pi in any wrap; an empty scan has no angle."""
    scan = at(1.0, beam, angle_min=angle_min, angle_max=angle_min + 2 * math.pi)
    c = ReadingCoverage().add([scan, make_scan()], 0.5, 0.005)
    assert c.angle_near_pi == int(near)


def test_angle_of_a_tie_is_the_first_beam() -> None:
    """Two beams hold the minimum: the first one's angle counts (the oracle's index)."""
    c = ReadingCoverage().add([make_scan({180: 1.0, 0: 1.0})], 0.5, 0.005)
    assert c.angle_near_pi == 1
    c = ReadingCoverage().add([make_scan({180: 1.0, 359: 1.5})], 0.5, 0.005)
    assert c.angle_near_pi == 0


# -- the threshold ------------------------------------------------------------


@pytest.mark.parametrize(
    ("distance", "near"),
    [(0.45, True), (0.4, True), (0.6, True), (0.502, False), (0.498, False), (0.62, False)],
)
def test_near_threshold_is_just_outside_the_band(distance: float, near: bool) -> None:
    """band 0.005 m (no noise): near = 0.005 < |d - 0.5| <= 0.105."""
    assert coverage_of([run_of([at(distance)])]).near_threshold == int(near)


def test_noise_widens_the_band_and_moves_near_with_it() -> None:
    """noise 0.05 m: band 0.15 m, so 0.6 m is inside it and 0.7 m just outside."""
    scans = [at(0.6), at(0.7), at(0.8)]
    assert coverage_of([run_of(scans, noise_sigma=0.05)]).near_threshold == 1
    assert coverage_of([run_of(scans)]).near_threshold == 1  # 0.6 only


@pytest.mark.parametrize(
    ("distances", "clears"),
    [
        ([0.3, 0.8], 1),
        ([0.3, None], 1),  # nothing in range: not due
        ([0.3, 0.502, 0.8], 1),  # the band leaves the warning as it was
        ([0.3, 0.502, 0.3], 0),
        ([0.8, 0.3], 0),
        ([0.3, 0.8, 0.3, 0.8], 2),
        ([0.3, 0.3, 0.3], 0),
    ],
)
def test_warning_clears_after_it_was_due(distances: list[float | None], clears: int) -> None:
    scans = [make_scan() if d is None else at(d) for d in distances]
    assert coverage_of([run_of(scans)]).warning_clears == clears


def test_a_clear_is_counted_within_one_run_only() -> None:
    """One run ends with the warning due, the next starts clear: no clear."""
    results = [run_of([at(0.8), at(0.3)], name="a"), run_of([at(0.8)], name="b")]
    assert coverage_of(results).warning_clears == 0


def test_the_run_threshold_decides() -> None:
    """0.35 m is due under a 0.4 m threshold, not under 0.3 m."""
    scans = [at(0.35), at(0.9)]
    assert coverage_of([run_of(scans, 0.4)]).warning_clears == 1
    assert coverage_of([run_of(scans, 0.3)]).warning_clears == 0


# -- what counts as delivered -------------------------------------------------


def test_dropped_and_lost_scans_are_not_counted() -> None:
    """Only scans the node received count."""
    nan = make_scan(fill=math.nan)
    deliveries = [Delivery(), Delivery(kind="dropped"), Delivery(), Delivery(kind="duplicate")]
    result = run_of([at(1.0), nan, nan, at(2.0)], deliveries=deliveries, lost={2})
    c = coverage_of([result])
    assert c.scans == 2
    assert cases_hit(c)["nan"] == (0, 0)


def test_a_run_without_records_counts_nothing() -> None:
    result = RunResult("not_run", "inprocess", 0, 0.5, "clean", not_run=True)
    assert coverage_of([result]).as_dict() == ReadingCoverage().as_dict()


# -- shape, sums, gaps --------------------------------------------------------


def test_json_shape_is_stable() -> None:
    c = coverage_of([run_of([at(0.45), make_scan({3: math.nan}, fill=3.0)])])
    d = c.as_dict()
    assert list(d) == [
        "scans",
        "cases",
        "near_threshold",
        "angle_near_pi",
        "angle_min_zero",
        "angle_min_minus_pi",
        "warning_clears",
    ]
    assert list(d["cases"]) == list(CASES)
    assert all(list(v) == ["beside_valid", "without_valid"] for v in d["cases"].values())
    assert d["scans"] == 2 and d["cases"]["nan"] == {"beside_valid": 1, "without_valid": 0}
    assert d["near_threshold"] == 1 and d["angle_min_minus_pi"] == 2 and d["warning_clears"] == 1
    assert json.loads(json.dumps(d, allow_nan=False)) == d


def test_per_scenario_and_total_agree() -> None:
    """Per scenario in run order (one name's runs summed); merged, they are the total."""
    results = [
        run_of([at(0.3), at(0.8)], name="b"),
        run_of([make_scan(fill=math.nan)], name="a"),
        run_of([at(0.3), make_scan()], name="b"),
    ]
    per = coverage_by_scenario(results)
    assert list(per) == ["b", "a"]
    assert per["b"].scans == 4 and per["b"].warning_clears == 2
    merged = ReadingCoverage()
    for c in per.values():
        merged.merge(c)
    assert merged.as_dict() == coverage_of(results).as_dict()


def test_gaps_name_what_is_missing() -> None:
    """One plain line per missing item; none once every item was delivered."""
    assert gaps(ReadingCoverage()) == [
        "no scan was delivered: the suite shows nothing about how a node reads scans"
    ]
    c = coverage_of([run_of([at(0.3), at(0.8)])])
    lines = gaps(c)
    assert "no scan has NaN beside a valid return: a node that filters inf but not NaN passes" in (
        lines
    )
    assert not any("clears a due warning" in line for line in lines)
    assert len(lines) == 2 * len(CASES) - 1 + 3  # +inf beside is there; near, pi, angle_min 0
    full = [
        make_scan({100: 2.0}, fill=VALUE[case], angle_min=0.0, angle_max=2 * math.pi)
        for case in CASES
    ] + [make_scan(fill=VALUE[case]) for case in CASES]
    full += [at(0.45), at(0.3, 0), at(0.8)]
    assert gaps(coverage_of([run_of(full)])) == []
