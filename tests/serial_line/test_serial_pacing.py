"""LinePacer's timing, driven by a fake clock: due times are exact arithmetic."""

from __future__ import annotations

import pytest

from harness.serial_line.pacing import LinePacer, p99

pytestmark = pytest.mark.timeout(10)

BYTE_115200 = 10 / 115200  # 8N1: 10 bits a byte


def drain(pacer: LinePacer, total: int, start: float, late: float = 0.0) -> list[tuple[float, int]]:
    """Write `total` bytes, each chunk at its due time (+ `late`); the (time, size) list."""
    writes = []
    now = start
    left = total
    while left:
        now = max(now, pacer.due(now) + late)
        n = pacer.allowance(left, now)
        assert n > 0
        pacer.sent(n, now)
        writes.append((now, n))
        left -= n
    return writes


def test_chunks_are_about_a_millisecond_of_line_time() -> None:
    assert LinePacer(115200).chunk_bytes == 11  # 11 * 86.8 us = 0.95 ms
    assert LinePacer(230400).chunk_bytes == 23
    assert LinePacer(300).chunk_bytes == 1
    assert LinePacer(115200, 11).byte_time_s == pytest.approx(11 / 115200)


def test_due_times_follow_the_burst_start_exactly() -> None:
    pacer = LinePacer(115200)
    assert pacer.due(100.0) == 100.0  # idle line: now
    assert pacer.allowance(50, 100.0) == 11
    writes = drain(pacer, 110, 100.0)
    assert [n for _, n in writes] == [11] * 10
    for k, (t, _) in enumerate(writes):
        assert t == pytest.approx(100.0 + k * 11 * BYTE_115200, abs=1e-12)
    assert pacer.free_at() == pytest.approx(100.0 + 110 * BYTE_115200, abs=1e-12)
    # Not yet due: nothing may go; exactly due: a chunk may.
    free = pacer.free_at()
    assert pacer.allowance(5, free - 1e-6) == 0
    assert pacer.allowance(5, free) == 5


def test_small_lateness_is_caught_up_without_drift() -> None:
    pacer = LinePacer(115200, max_lag_s=0.005)
    writes = drain(pacer, 1100, 0.0, late=0.0002)  # every wake-up 0.2 ms late
    # Due times stay on the grid from the burst start (the first write, at
    # 0.2 ms): lateness does not add up.
    start = writes[0][0]
    assert start == pytest.approx(0.0002)
    assert pacer.free_at() == pytest.approx(start + 1100 * BYTE_115200, abs=1e-12)
    last_t, last_n = writes[-1]
    assert last_t == pytest.approx(start + (1100 - last_n) * BYTE_115200 + 0.0002, abs=1e-12)
    report = pacer.report()
    assert report.mean_rate_error_pct == pytest.approx(0.0, abs=0.5)


def test_a_long_stall_starts_a_new_burst_instead_of_bursting() -> None:
    pacer = LinePacer(115200, max_lag_s=0.005)
    drain(pacer, 110, 0.0)
    stall_end = pacer.free_at() + 0.1  # the writer was away for 100 ms
    assert pacer.due(stall_end) == stall_end
    pacer.sent(11, stall_end)
    assert pacer.free_at() == pytest.approx(stall_end + 11 * BYTE_115200, abs=1e-12)
    assert pacer.allowance(11, stall_end + 1e-6) == 0  # no catch-up burst after a gap


def test_idle_gaps_do_not_count_against_the_rate() -> None:
    pacer = LinePacer(115200)
    drain(pacer, 550, 0.0)
    drain(pacer, 550, 1.0)  # a second burst a second later
    report = pacer.report()
    assert report.bytes_paced == 1100
    assert report.achieved_bytes_per_s == pytest.approx(11520.0, rel=1e-9)
    assert report.mean_rate_error_pct == pytest.approx(0.0, abs=1e-6)


def test_a_slow_writer_shows_as_rate_error() -> None:
    pacer = LinePacer(115200, max_lag_s=1.0)
    # Each chunk written 10 % of its line time late, and never caught up.
    now = 0.0
    for _ in range(100):
        pacer.sent(11, now)
        now += 11 * BYTE_115200 * 1.1
    report = pacer.report()
    assert report.mean_rate_error_pct == pytest.approx(100 / 1.1 - 100, abs=1e-6)


def test_revolution_jitter_against_the_nominal_period() -> None:
    pacer = LinePacer(115200)
    for t in (0.0, 0.1, 0.2005, 0.3, 0.4):
        pacer.mark_revolution(t)
    report = pacer.report(0.1)
    assert report.revolutions == 5
    assert report.period_jitter_p99_ms == pytest.approx(0.5, abs=1e-9)
    assert report.period_mean_ms == pytest.approx(100.0)
    assert LinePacer(115200).report(0.1).period_jitter_p99_ms is None


def test_p99_is_nearest_rank() -> None:
    assert p99([3.0]) == 3.0
    assert p99([float(i) for i in range(1, 101)]) == 99.0
    assert p99([float(i) for i in range(1, 11)]) == 10.0


def test_bad_line_settings_are_refused() -> None:
    with pytest.raises(ValueError):
        LinePacer(0)
