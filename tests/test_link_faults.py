"""Link faults: delivery plans, rate drift, serial line damage and their parsing (pure)."""

from __future__ import annotations

import math
from collections.abc import Callable
from itertools import islice

import numpy as np
import pytest

from harness.errors import ConfigError
from harness.faults.link import (
    Delay,
    Delivery,
    Drop,
    Duplicate,
    LineCorruption,
    LineDamage,
    LineDrops,
    LineNoise,
    LinkFaults,
    RateDrift,
    Reorder,
    StaleStamps,
    damage_bytes,
    plan_deliveries,
    scan_periods,
)
from harness.faults.sensor import Noise, build_profile, split_fault_text
from harness.lidar.spec import PRESETS

GAZEBO = PRESETS["gazebo"]
N = 5000  # frames or periods for the rate checks: about 4.7 sigma of room at 10%
EVERYTHING = LinkFaults(
    (Drop(0.1), Duplicate(0.1), Reorder(0.1), StaleStamps(0.2, 1.0), Delay(0.05, 0.03))
)

Plan = list[tuple[int, Delivery]]


def plan(faults: LinkFaults, seed: int = 0, n: int = N) -> Plan:
    return list(plan_deliveries(range(n), faults, seed))


def share(items: Plan, kind: str, n: int = N) -> float:
    return sum(d.kind == kind for _, d in items) / n


def line_bytes(n: int = 20000, seed: int = 99) -> bytes:
    return np.random.default_rng(seed).integers(0, 256, n, dtype=np.uint8).tobytes()


# -- plan_deliveries -----------------------------------------------------------


def test_plan_same_seed_same_plan() -> None:
    """A run is replayable: the same seed plans every delivery the same way."""
    assert plan(EVERYTHING, seed=7, n=1000) == plan(EVERYTHING, seed=7, n=1000)


def test_plan_different_seed_differs() -> None:
    """The seed matters: another seed gives another plan."""
    assert plan(EVERYTHING, seed=7, n=1000) != plan(EVERYTHING, seed=8, n=1000)


def test_plan_without_faults_is_plain() -> None:
    """No link faults: each frame goes out once, in order, on time, fresh."""
    assert plan(LinkFaults(), n=100) == [(i, Delivery("sent", 0.0, 0.0)) for i in range(100)]


def test_plan_keeps_every_frame_and_duplicates_follow() -> None:
    """Every frame is accounted for once (dropped ones too, to judge "no answer"),
    and a duplicate comes right after its original."""
    items = plan(EVERYTHING)
    firsts = sorted(frame for frame, d in items if d.kind != "duplicate")
    assert firsts == list(range(N))
    assert {d.kind for _, d in items} == {"sent", "dropped", "duplicate", "reordered"}
    for j, (frame, d) in enumerate(items):
        if d.kind == "duplicate":
            before_frame, before = items[j - 1]
            assert (before_frame, before.kind) == (frame, "sent")
            assert before.stamp_age_s == d.stamp_age_s


@pytest.mark.parametrize(
    "faults", [LinkFaults((Reorder(0.2),)), EVERYTHING], ids=["reorder", "everything"]
)
def test_reordered_frame_follows_its_successor(faults: LinkFaults) -> None:
    """A reordered frame arrives just after the frame that followed it in the input
    (after that frame's delivery, dropped or duplicated, whichever came last)."""
    items = plan(faults)
    reordered = [j for j, (_, d) in enumerate(items) if d.kind == "reordered"]
    assert reordered
    for j in reordered:
        if items[j][0] == N - 1:
            continue  # the last frame has no successor: it comes out at the end
        assert items[j - 1][0] == items[j][0] + 1


@pytest.mark.parametrize(
    "fault, kind",
    [(Drop(0.1), "dropped"), (Duplicate(0.1), "duplicate"), (Reorder(0.1), "reordered")],
)
def test_plan_rates_roughly_honoured(fault: Drop | Duplicate | Reorder, kind: str) -> None:
    """A rate of 10% affects about 10% of the frames over 5000 of them."""
    assert 0.08 <= share(plan(LinkFaults((fault,))), kind) <= 0.12


@pytest.mark.parametrize("mean, jitter", [(0.05, 0.03), (0.01, 0.03), (0.2, 0.0)])
def test_delay_within_jitter_and_never_negative(mean: float, jitter: float) -> None:
    """Delays spread over [mean - jitter, mean + jitter], clipped at 0, never negative."""
    delays = np.array([d.delay_s for _, d in plan(LinkFaults((Delay(mean, jitter),)))])
    eps = 1e-12
    assert delays.min() >= max(0.0, mean - jitter) - eps
    assert delays.max() <= mean + jitter + eps
    assert np.all(delays >= 0.0)
    if jitter:
        assert delays.std() > jitter / 4  # it really spreads
    else:
        assert np.all(delays == mean)


def test_stale_stamps_age_and_rate() -> None:
    """About `rate` of the scans carry a stamp exactly `age` s old; the rest are fresh."""
    items = plan(LinkFaults((StaleStamps(0.2, 1.5),)))
    ages = [d.stamp_age_s for _, d in items]
    assert set(ages) == {0.0, 1.5}
    assert 0.18 <= ages.count(1.5) / N <= 0.22


def test_other_kinds_do_not_change_drops() -> None:
    """Each kind draws from fixed slots: adding faults keeps the same frames dropped."""

    def dropped(faults: LinkFaults) -> set[int]:
        return {frame for frame, d in plan(faults, seed=3) if d.kind == "dropped"}

    alone = dropped(LinkFaults((Drop(0.1),)))
    assert alone
    assert dropped(LinkFaults((Drop(0.1), Duplicate(0.3)))) == alone
    crowded = LinkFaults((Drop(0.1), Duplicate(0.3), StaleStamps(0.5), Delay(0.1, 0.1)))
    assert dropped(crowded) == alone


@pytest.mark.parametrize(
    "delivery, ignorable, words",
    [
        (Delivery(), False, []),
        (Delivery("dropped"), False, ["dropped by the link: no answer expected"]),
        (Delivery("duplicate"), True, ["a second copy of this scan", "no answer accepted too"]),
        (Delivery("reordered"), True, ["delivered after the next scan", "no answer accepted too"]),
        (Delivery("sent", 0.05), False, ["delivered 0.050 s late"]),
        (Delivery("sent", 0.0, 1.0), True, ["stamped 1 s in the past", "no answer accepted too"]),
    ],
    ids=["sent", "dropped", "duplicate", "reordered", "late", "stale"],
)
def test_delivery_words_and_leniency(delivery: Delivery, ignorable: bool, words: list[str]) -> None:
    """Reports say what happened to a scan; the oracle accepts silence only where
    the node may rightly skip the scan (seen already, newer seen, or stale)."""
    assert delivery.may_be_ignored is ignorable
    assert delivery.delivered is (delivery.kind != "dropped")
    text = delivery.describe()
    if not words:
        assert text == ""
    for word in words:
        assert word in text
    if not ignorable:
        assert "no answer accepted" not in text


# -- scan_periods --------------------------------------------------------------


def periods(drift: RateDrift, n: int, seed: int = 0, nominal: float = 10.0) -> list[float]:
    return list(islice(scan_periods(drift, nominal, seed), n))


def test_periods_within_bounds() -> None:
    """The rate never leaves [min_hz, max_hz], so periods stay in [1/max, 1/min]."""
    for seed in range(5):
        got = np.array(periods(RateDrift(), N, seed))
        assert got.min() >= 1 / 6.7 and got.max() <= 1 / 3.3


def test_periods_deterministic() -> None:
    """Same seed, same periods; another seed, other periods."""
    assert periods(RateDrift(), 200, 4) == periods(RateDrift(), 200, 4)
    assert periods(RateDrift(), 200, 4) != periods(RateDrift(), 200, 5)


def test_periods_start_at_clamped_nominal() -> None:
    """A 10 Hz nominal rate above the lab range starts at its top, 6.7 Hz."""
    assert periods(RateDrift(), 1)[0] == 1 / 6.7


def test_periods_fixed_when_range_is_a_point() -> None:
    """min_hz == max_hz: no room to drift, every period is the same."""
    assert set(periods(RateDrift(5.0, 5.0), 50)) == {0.2}


def test_rate_actually_drifts() -> None:
    """The rate keeps moving and wanders across the whole range, not stuck at one end."""
    assert len(set(periods(RateDrift(), 200))) > 20
    rates = 1 / np.array(periods(RateDrift(), 2000, seed=1))
    third = (6.7 - 3.3) / 3
    assert np.any(rates < 3.3 + third) and np.any(rates > 6.7 - third)


# -- LineDamage / damage_bytes -------------------------------------------------


def test_line_without_faults_is_untouched() -> None:
    """No line faults: the bytes arrive as written and nothing is counted."""
    line = LineDamage(LinkFaults((Drop(0.5),)), 0)
    data = line_bytes(1000)
    assert not line
    assert line.damage(data) == data
    assert (line.flipped, line.dropped, line.noise_bytes) == (0, 0, 0)


def test_corruption_flips_one_bit_per_hit_byte() -> None:
    """Corruption keeps the length and flips exactly one bit in about `rate` of the bytes."""
    line = LineDamage(LinkFaults((LineCorruption(0.05),)), 1)
    data = line_bytes()
    out = damage_bytes(data, line)
    assert len(out) == len(data)
    xor = np.frombuffer(data, np.uint8) ^ np.frombuffer(out, np.uint8)
    bits = np.unpackbits(xor[:, None], axis=1).sum(axis=1)
    assert set(np.unique(bits)) <= {0, 1}
    assert int(bits.sum()) == line.flipped
    assert 0.04 <= line.flipped / len(data) <= 0.06


def test_drops_lose_about_rate_of_bytes() -> None:
    """Drops lose about `rate` of the bytes, keep the rest in order, and count the loss."""
    line = LineDamage(LinkFaults((LineDrops(0.05),)), 2)
    data = line_bytes()
    out = line.damage(data)
    assert len(out) == len(data) - line.dropped
    assert 0.04 <= line.dropped / len(data) <= 0.06
    rest = iter(data)
    assert all(byte in rest for byte in out)  # a subsequence of the input


def test_noise_inserts_one_burst() -> None:
    """Noise at rate 1.0 inserts exactly `length` bytes in one place each call."""
    line = LineDamage(LinkFaults((LineNoise(1.0, 16),)), 3)
    data = line_bytes(500)
    for call in range(1, 4):
        out = line.damage(data)
        assert len(out) == len(data) + 16
        assert line.noise_bytes == 16 * call
        assert any(out[:at] + out[at + 16 :] == data for at in range(len(data) + 1))


def test_line_damage_deterministic() -> None:
    """Same seed, same damage call after call; another seed, other damage."""
    faults = LinkFaults((LineCorruption(0.05), LineDrops(0.05), LineNoise(0.5, 8)))
    data = line_bytes(2000)

    def run(seed: int) -> list[bytes]:
        line = LineDamage(faults, seed)
        return [line.damage(data) for _ in range(5)]

    assert run(11) == run(11)
    assert run(11) != run(12)


# -- parameter validation ------------------------------------------------------

NAN = math.nan


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Delay(mean=3), "delay mean"),
        (lambda: Delay(mean=-0.1), "delay mean"),
        (lambda: Delay(mean=0.1, jitter=1.5), "delay jitter"),
        (lambda: Delay(mean=NAN), "delay mean"),
        (lambda: Delay(mean=True), "delay mean"),
        (lambda: Drop(rate=1.5), "drop rate"),
        (lambda: Drop(rate=NAN), "drop rate"),
        (lambda: Drop(rate=True), "drop rate"),
        (lambda: Duplicate(rate=-0.1), "duplicate rate"),
        (lambda: Reorder(rate=2), "reorder rate"),
        (lambda: RateDrift(min_hz=7, max_hz=3), r"min_hz \(7\) is above max_hz \(3\)"),
        (lambda: RateDrift(max_hz=100), "rate_drift max_hz"),
        (lambda: RateDrift(min_hz=0.1), "rate_drift min_hz"),
        (lambda: RateDrift(max_hz=NAN), "rate_drift max_hz"),
        (lambda: RateDrift(min_hz=True), "rate_drift min_hz"),
        (lambda: StaleStamps(rate=0.1, age=0), "stale_stamps age"),
        (lambda: StaleStamps(rate=0.1, age=NAN), "stale_stamps age"),
        (lambda: StaleStamps(rate=1.1), "stale_stamps rate"),
        (lambda: LineCorruption(rate=0.5), "line_corruption rate"),
        (lambda: LineDrops(rate=0.2), "line_drops rate"),
        (lambda: LineNoise(rate=0.1, length=0), "line_noise length"),
        (lambda: LineNoise(rate=0.1, length=2000), "line_noise length"),
        (lambda: LineNoise(rate=0.1, length=True), "line_noise length"),
        (lambda: LineNoise(rate=0.1, length=2.0), "line_noise length"),
        (lambda: LineNoise(rate=NAN), "line_noise rate"),
    ],
)
def test_link_faults_reject_nonsense(make: Callable[[], object], message: str) -> None:
    """Out-of-range, NaN and boolean parameters fail with a ConfigError naming the field."""
    with pytest.raises(ConfigError, match=message):
        make()


# -- build_profile with link kinds ----------------------------------------------


@pytest.mark.parametrize(
    "name, kinds",
    [
        ("slow_link", ["delay"]),
        ("lossy_link", ["drop", "duplicate", "reorder"]),
        ("drifting_rate", ["rate_drift"]),
        ("stale_stamps", ["stale_stamps"]),
        ("noisy_line", ["line_corruption", "line_drops", "line_noise"]),
    ],
)
def test_named_link_profiles(name: str, kinds: list[str]) -> None:
    """Each named link profile fills FaultProfile.link and leaves the scan faults alone."""
    profile = build_profile([name])
    assert [f.kind for f in profile.link.items] == kinds
    assert profile.faults == () and profile.convention == "rep117"
    assert profile.link.on_line is (name == "noisy_line")
    assert profile.link.stale_stamps is (name == "stale_stamps")


def test_inline_mapping_link_fault() -> None:
    """A scenario can write a link fault as a mapping, like the scan faults."""
    profile = build_profile([{"type": "drop", "rate": 0.1}])
    assert profile.link == LinkFaults((Drop(0.1),))
    assert profile.name == "drop(rate=0.1)"


def test_inline_text_link_fault() -> None:
    """On a command line, "kind(key=value,...)" is the same inline fault."""
    profile = build_profile(["delay(mean=0.05,jitter=0.01)"])
    assert profile.link == LinkFaults((Delay(0.05, 0.01),))
    assert profile.name == "delay(mean=0.05,jitter=0.01)"
    assert build_profile(["line_noise(rate=0.1,length=8)"]).link == LinkFaults((LineNoise(0.1, 8),))


def test_scan_and_link_faults_combine() -> None:
    """Scan faults and link faults sit side by side and both show in the report line."""
    profile = build_profile(["noisy", "drop(rate=0.1)"])
    assert profile.faults == (Noise(0.01),)
    assert profile.link == LinkFaults((Drop(0.1),))
    text = profile.describe()
    assert text.startswith("noisy+drop(rate=0.1): ")
    assert "gaussian range noise" in text and "10% of scans dropped" in text


@pytest.mark.parametrize(
    "items, message",
    [
        ([{"type": "drop", "rate": 0.1, "seed": 1}], r"faults\[0\]: unknown key 'seed' for drop"),
        (["noisy", "drop(rate=0.1,seed=1)"], r"faults\[1\]: unknown key 'seed' for drop"),
        ([{"type": "delay", "mean": "x", "jitter": 0}], r"faults\[0\]\.mean: must be a number"),
        (["drop(rate=lots)"], r"faults\[0\]\.rate: must be a number"),
        (["line_noise(rate=0.1,length=2.5)"], r"faults\[0\]\.length: must be a whole number"),
        (["noisy", "drop(rate=0.1"], r"faults\[1\]: 'drop\(rate=0\.1': expected KIND\(KEY=VALUE"),
        (["drop(0.1)"], r"faults\[0\]: .* expected KEY=VALUE"),
        ([{"type": "line_corruption", "rate": 0.5}], r"faults\[0\]: line_corruption rate"),
        (["delay(mean=3,jitter=0)"], r"faults\[0\]: delay mean must be in"),
    ],
)
def test_link_config_errors(items: list[object], message: str) -> None:
    """Each mistake is a ConfigError naming the item, faults[i], and the field."""
    with pytest.raises(ConfigError, match=message):
        build_profile(items)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "text", ["dropouts(rate=0.1,value=nan)", "dropouts(rate=0.1,value=inf)", "convention(name=nan)"]
)
def test_inline_text_keeps_word_values(text: str) -> None:
    """Words that look like floats ("nan", "inf") stay words where a string is expected."""
    build_profile([text])


@pytest.mark.parametrize(
    "text, expected",
    [
        ("delay(mean=0.05)", Delay(0.05)),
        ("stale_stamps(rate=0.1)", StaleStamps(0.1)),
        ("line_noise(rate=0.1)", LineNoise(0.1)),
        ("rate_drift()", RateDrift()),
    ],
)
def test_inline_uses_class_defaults(text: str, expected: object) -> None:
    """Keys with a default on the fault class may be left out inline."""
    assert build_profile([text]).link == LinkFaults((expected,))  # type: ignore[arg-type]


# -- split_fault_text ------------------------------------------------------------


def test_split_keeps_commas_in_parentheses() -> None:
    """A comma inside "(...)" belongs to the item, not the list."""
    text = "noisy,drop(rate=0.1),delay(mean=0.05,jitter=0.01)"
    assert split_fault_text(text) == ["noisy", "drop(rate=0.1)", "delay(mean=0.05,jitter=0.01)"]


def test_split_drops_blank_items() -> None:
    """Stray commas and spaces leave no empty items behind."""
    assert split_fault_text(" noisy, ,,drop(rate=0.1) ,") == ["noisy", "drop(rate=0.1)"]
    assert split_fault_text("") == []


# -- scans are unchanged by link faults ----------------------------------------


def test_link_faults_leave_scans_alone() -> None:
    """Link faults use their own streams: the emitted scans are byte-identical with them."""
    truth = np.full(GAZEBO.samples, np.inf)
    truth[: GAZEBO.samples // 2] = np.linspace(0.5, 5.0, GAZEBO.samples // 2)
    plain, lossy = build_profile(["noisy"]), build_profile(["noisy", "lossy_link"])
    a = plain.emit(truth, GAZEBO, np.random.default_rng(5), stamp=1.0)
    b = lossy.emit(truth, GAZEBO, np.random.default_rng(5), stamp=1.0)
    assert a.ranges.tobytes() == b.ranges.tobytes()
    assert a.intensities.tobytes() == b.intensities.tobytes()
