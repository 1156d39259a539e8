"""The bench's pure figures: percentiles, overhead, line rates, targets."""

from __future__ import annotations

import pytest

from harness.bench.figures import check_targets, figures
from harness.bench.run import STAGES, parse_stages
from harness.bench.stage import StageResult
from harness.bench.stats import (
    RPLIDAR_SCAN_DESCRIPTOR,
    arrival_rate,
    jitter_ms,
    jitter_p99_ms,
    median,
    overhead_ratio,
    percentile,
    read_times,
    rplidar_revolution_starts,
)
from harness.devices.revolution import Sample
from harness.devices.rplidar import RplidarDevice
from harness.errors import ConfigError


def test_percentile_is_nearest_rank() -> None:
    assert percentile([5.0], 99) == 5.0
    assert percentile([float(i) for i in range(1, 101)], 99) == 99.0
    assert percentile([float(i) for i in range(1, 11)], 99) == 10.0  # under 100: the maximum
    assert percentile([3.0, 1.0, 2.0], 50) == 2.0
    with pytest.raises(ValueError, match="no values"):
        percentile([], 50)
    with pytest.raises(ValueError, match="q must be"):
        percentile([1.0], 0)


def test_median_of_even_and_odd_counts() -> None:
    assert median([3.0, 1.0, 2.0]) == 2.0
    assert median([4.0, 1.0, 2.0, 3.0]) == 2.5


def test_overhead_is_what_is_left_over_the_floor() -> None:
    # 3 ms a scan, of which 0.5 ms ray casting and 1.5 ms round trip: 1 ms over 2 ms.
    assert overhead_ratio(0.003, 0.0005, 0.0015) == pytest.approx(0.5)
    assert overhead_ratio(0.002, 0.0005, 0.0015) == pytest.approx(0.0)
    with pytest.raises(ValueError):
        overhead_ratio(0.001, 0.0, 0.0)


def test_jitter_against_the_period() -> None:
    assert jitter_ms([0.0, 0.1, 0.2015, 0.3], 0.1) == pytest.approx([0.0, 1.5, 1.5], abs=1e-9)
    assert jitter_p99_ms([0.0, 0.1, 0.2015, 0.3], 0.1) == pytest.approx(1.5)
    assert jitter_p99_ms([0.0], 0.1) is None


def test_revolution_starts_in_an_emulated_rplidar_stream() -> None:
    device = RplidarDevice()
    device.set_motor(True)
    head = device.receive(bytes((0xA5, 0x20)))
    assert head == RPLIDAR_SCAN_DESCRIPTOR
    rev = [Sample(angle_deg=i * 36.0, distance_mm=1000.0, quality=47) for i in range(10)]
    stream = head + device.encode_revolution(rev) + device.encode_revolution(rev)
    assert rplidar_revolution_starts(stream) == [7, 7 + 50]
    with pytest.raises(ValueError, match="descriptor"):
        rplidar_revolution_starts(stream[1:])


def test_read_times_name_the_read_that_brought_each_byte() -> None:
    reads = [(1.0, 10), (2.0, 10), (3.0, 5)]
    assert read_times(reads, [0, 9, 10, 24, 25]) == [1.0, 1.0, 2.0, 3.0]


def test_arrival_rate_counts_busy_stretches_only() -> None:
    # Two stretches of 100 bytes at 1000 B/s, 10 bytes a read, a long gap between.
    reads = [(k * 0.01, 10) for k in range(10)] + [(5.0 + k * 0.01, 10) for k in range(10)]
    assert arrival_rate(reads, [(0, 100), (100, 200)]) == pytest.approx(1000.0)
    assert arrival_rate(reads[:1], [(0, 100)]) is None


def stage(name: str, scans: int, seconds: float, **extra: float) -> StageResult:
    return StageResult(name, scans, seconds, scans * 0.1, extra=dict(extra))


def test_figures_ratios_and_targets() -> None:
    stages = {
        "raycast": stage("raycast", 100, 0.05, truth_ms=0.6),
        "inprocess": stage("inprocess", 100, 0.1),
        "ros2": stage(
            "ros2",
            100,
            0.3,
            round_trip_ms_median=1.0,
            round_trip_ms_p99=2.0,
            overhead_ratio=overhead_ratio(0.003, 0.0005, 0.001),
        ),
    }
    values = figures(stages, 300.0)
    assert values["raycast_scans_per_s"] == pytest.approx(2000.0)
    assert values["ratio_to_raycast"]["ros2_lockstep"] == pytest.approx(6.0)
    assert values["real_time_factor"]["inprocess"] == pytest.approx(100.0)
    # 3 ms a scan, 0.5 ms ray casting, 1 ms round trip: (3 - 1.5) / 1.5, as the stage said.
    assert values["overhead_ratio"] == pytest.approx(1.0)
    assert values["serial_lockstep_scans_per_s"] is None
    targets = {t["key"]: t["met"] for t in check_targets(values)}
    assert targets["ros2_lockstep_scans_per_s"] is False  # 333 scans/s
    assert targets["overhead_ratio"] is False
    assert targets["serial_jitter_p99_ms"] is None  # not measured


def test_only_names_known_stages_in_bench_order() -> None:
    assert parse_stages(None) == STAGES
    assert parse_stages("ros2, raycast") == ("raycast", "ros2")
    with pytest.raises(ConfigError, match="unknown stage foo"):
        parse_stages("raycast,foo")
