"""Every delivery link fault over real DDS, with a real node process.

Each test runs the shipped `approach_wall` scenario through the ros2 link
(the bundled reference node, or a buggy student node) with one link fault,
and checks both that the run is judged right and that the fault really
happened as planned: late, lost, twice, out of order, at a drifting rate,
with old stamps.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from itertools import pairwise
from pathlib import Path

import pytest

from harness.judge.oracle import Oracle
from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.record import read_scans, write_recording
from harness.report.summary import json_bytes, scenario_details
from harness.runner.scenario_run import run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]

SCENARIO = "approach_wall"  # about 95 scans at 10 Hz, crossing the 0.5 m threshold
SEED = 0
STUDENT = Path(__file__).parent / "student_node.py"


def student(variant: str) -> LinkOptions:
    """A student-style node with one bug (see student_node.py), as its own process."""
    return LinkOptions(node=f"{sys.executable} {STUDENT} {variant}")


def run_ros2(faults: list[str], options: LinkOptions | None = None, seed: int = SEED) -> RunResult:
    """One run of the scenario over ros2; it must start and reach its last tick."""
    settings = RunSettings(seed=seed, faults=faults)
    result = run(resolve_scenario(SCENARIO), "ros2", options or LinkOptions(), settings)
    assert not result.not_started, (result.error, result.diagnostics)
    return result


def passes(result: RunResult) -> None:
    assert result.error is None, (result.error, result.diagnostics)
    assert result.ok, result.first_failure
    assert result.records


def kinds(result: RunResult) -> Counter[str]:
    return Counter(r.delivery.kind for r in result.records)


def test_delay_with_jitter_delays_each_scan_and_the_run() -> None:
    """delay(0.02, 0.01): every scan waits 0.01..0.03 s before it goes out, the
    answers still count (timed from the send), and the run takes that much longer."""
    mean, jitter = 0.02, 0.01
    result = run_ros2([f"delay(mean={mean}, jitter={jitter})"])
    passes(result)
    delays = [r.delivery.delay_s for r in result.records if r.delivery.delivered]
    assert len(delays) == len(result.records)
    assert all(mean - jitter - 1e-12 <= d <= mean + jitter + 1e-12 for d in delays), delays
    assert max(delays) - min(delays) > jitter / 2  # the jitter really spreads them
    assert all(r.answers.statuses for r in result.records)  # each late scan was answered
    assert result.wall_s >= sum(delays)


def test_dropped_scans_expect_no_answer_and_are_not_recorded(tmp_path: Path) -> None:
    """drop(0.2): dropped ticks never reach the node, get no answer, and pass; the
    recording and the per-tick trace hold a scan only for the delivered ticks."""
    result = run_ros2(["drop(rate=0.2)"])
    passes(result)
    dropped = [r for r in result.records if r.delivery.kind == "dropped"]
    assert dropped and len(dropped) < len(result.records)
    assert set(kinds(result)) == {"sent", "dropped"}
    for r in dropped:
        assert not r.answers.statuses and not r.answers.warnings
        assert r.verdict.ok and r.verdict.claim is None and r.verdict.explanation == ""
    delivered = len(result.records) - len(dropped)
    assert sum(1 for r in result.records if r.answers.statuses) == delivered

    recorded = read_scans(write_recording(tmp_path / "run.mcap", result))
    assert len(recorded.scans) == delivered
    assert recorded.run["ticks"] == str(len(result.records))
    stamps = [r.scan.stamp for r in result.records if r.delivery.delivered]
    assert [s.stamp for s in recorded.scans] == pytest.approx(stamps, abs=1e-6)

    trace = json.loads(json_bytes(scenario_details(result, {})))
    trace_kinds = Counter(entry["delivery"]["kind"] for entry in trace["records"])
    assert trace_kinds == {"sent": delivered, "dropped": len(dropped)}


def test_wrong_answers_still_fail_under_drops() -> None:
    """A node that inverts the warning is caught on the ticks that did reach it;
    the dropped ones stay "no answer expected"."""
    result = run_ros2(["drop(rate=0.2)"], student("inverted_bool"))
    assert result.error is None, (result.error, result.diagnostics)
    assert not result.ok
    failed = result.failed_ticks
    assert failed and all(r.delivery.delivered for r in failed)
    assert all(r.verdict.ok for r in result.records if not r.delivery.delivered)
    assert any(r.delivery.kind == "dropped" for r in result.records)
    first = result.first_failure
    assert first is not None and f"{SCENARIO}: t=" in first and " tick " in first
    assert "expected warning" in first, first


def test_duplicated_scans_are_answered_and_judged_each_time() -> None:
    """duplicate(0.2): a duplicated tick is recorded twice, the second copy marked
    "duplicate"; the reference node answers both copies and both are right."""
    result = run_ros2(["duplicate(rate=0.2)"])
    passes(result)
    records = result.records
    dup_at = [j for j, r in enumerate(records) if r.delivery.kind == "duplicate"]
    assert dup_at
    per_tick = Counter(r.tick for r in records)
    assert sorted(t for t, n in per_tick.items() if n == 2) == [records[j].tick for j in dup_at]
    assert max(per_tick.values()) == 2
    for j in dup_at:
        original, copy = records[j - 1], records[j]
        assert original.tick == copy.tick and original.delivery.kind == "sent"
        assert original.scan.to_bytes() == copy.scan.to_bytes()
        assert original.verdict.ok and copy.verdict.ok
        assert len(original.answers.statuses) == 1 and len(copy.answers.statuses) == 1
    assert [r.tick for j, r in enumerate(records) if j not in dup_at] == sorted(per_tick)


def test_reordered_scans_arrive_after_their_successor_and_are_judged_on_their_own_scan() -> None:
    """reorder(0.2): a held-back scan is recorded after the next one and judged
    against its own scan, not the one that overtook it."""
    result = run_ros2(["reorder(rate=0.2)"])
    passes(result)
    records = result.records
    oracle = Oracle(resolve_scenario(SCENARIO).threshold)
    moved = [j for j, r in enumerate(records) if r.delivery.kind == "reordered"]
    assert moved
    assert sorted(r.tick for r in records) == list(range(len(records)))  # each tick once
    differs = 0
    for j in moved:
        late, overtaker = records[j], records[j - 1]
        assert overtaker.tick == late.tick + 1
        own = oracle.expect(late.scan)
        assert late.verdict.expected.distance == own.distance
        assert late.verdict.expected == own
        assert late.scan.stamp == pytest.approx(late.t)
        assert late.answers.statuses and late.verdict.ok
        differs += own.distance != oracle.expect(overtaker.scan).distance
    assert differs  # the robot moved between them: a mix-up would have shown


def test_drifting_rate_spaces_scans_by_their_own_scan_time() -> None:
    """rate_drift(3.3, 6.7): each scan's scan_time is its period, within the
    drift's bounds and varying, and the next scan comes that much later."""
    lo, hi = 3.3, 6.7
    result = run_ros2([f"rate_drift(min_hz={lo}, max_hz={hi})"])
    passes(result)
    records = result.records
    times = [r.scan.scan_time for r in records]
    assert len({round(x, 6) for x in times}) > len(records) // 2  # it really drifts
    eps = 1e-6
    assert all(1 / hi - eps <= x <= 1 / lo + eps for x in times), (min(times), max(times))
    samples = records[0].scan.ranges.size
    for before, after in pairwise(records):
        assert after.t - before.t == pytest.approx(before.scan.scan_time, abs=1e-6)
        assert before.scan.time_increment == pytest.approx(before.scan.scan_time / samples)
    assert records[0].t == 0.0


def test_stale_stamps_are_old_by_their_age_and_still_answered_right() -> None:
    """stale_stamps(0.3, 1.0): a stale scan's stamp is its time minus the age
    (never below 0), the others are stamped on time; all are judged right."""
    age = 1.0
    result = run_ros2([f"stale_stamps(rate=0.3, age={age})"])
    passes(result)
    stale = [r for r in result.records if r.delivery.stamp_age_s > 0]
    fresh = [r for r in result.records if r.delivery.stamp_age_s == 0]
    assert stale and fresh
    assert any(r.t > age for r in stale) and all(r.delivery.kind == "sent" for r in stale)
    for r in stale:
        assert r.delivery.stamp_age_s == age
        assert r.scan.stamp == pytest.approx(max(0.0, r.t - age), abs=1e-9)
        assert r.answers.statuses and r.verdict.ok
    for r in fresh:
        assert r.scan.stamp == pytest.approx(r.t, abs=1e-9)


def test_same_seed_same_delivery_plan_over_ros2_and_inprocess() -> None:
    """lossy_link with one seed: ros2 and inprocess drop, duplicate and reorder
    the same ticks, and see the same scans."""
    seed = 1234
    settings = RunSettings(seed=seed, faults=["lossy_link"])
    inprocess = run(resolve_scenario(SCENARIO), "inprocess", LinkOptions(), settings)
    ros2 = run_ros2(["lossy_link"], seed=seed)
    passes(inprocess)
    passes(ros2)

    def plan(result: RunResult) -> list[tuple[int, str, float, float, bytes]]:
        return [
            (r.tick, r.delivery.kind, r.delivery.delay_s, r.delivery.stamp_age_s, r.scan.to_bytes())
            for r in result.records
        ]

    assert plan(ros2) == plan(inprocess)
    assert {"dropped", "duplicate", "reordered"} <= set(kinds(ros2))
    assert [r.verdict.ok for r in ros2.records] == [r.verdict.ok for r in inprocess.records]


def test_buggy_node_is_caught_under_lossy_and_slow_link() -> None:
    """lossy_link + slow_link: a node that inverts the warning fails, and each
    failing tick's explanation names the expectation and how the scan travelled;
    answers to duplicate and reordered scans must be right too."""
    result = run_ros2(["lossy_link", "slow_link"], student("inverted_bool"))
    assert result.error is None, (result.error, result.diagnostics)
    assert result.faults == "lossy_link+slow_link"
    assert not result.ok
    assert set(kinds(result)) == {"sent", "dropped", "duplicate", "reordered"}
    failed = result.failed_ticks
    assert failed
    for r in failed:
        text = r.verdict.explanation
        assert text.startswith(f"t={r.t:.2f} s tick {r.tick} ("), text
        assert "expected warning" in text and r.delivery.describe() in text, text
    assert any("delivered 0.0" in r.verdict.explanation for r in failed)
    for r in result.records:
        if r.delivery.kind == "dropped":
            assert r.verdict.ok
        elif r.verdict.expected.warning is not None:  # clear of the threshold band
            assert not r.verdict.ok, (r.tick, r.delivery, r.answers.warnings)
    copies = [r for r in failed if r.delivery.kind in ("duplicate", "reordered")]
    assert copies and all("no answer accepted too" in r.verdict.explanation for r in copies)
