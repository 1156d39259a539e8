"""The live judge: answers go to the scan before them, windows close, verdicts explain (pure)."""

from __future__ import annotations

import numpy as np

from harness.faults.sensor import build_profile
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult
from harness.lidar.scan import Scan
from harness.lidar.spec import preset
from harness.live.judge import GRACE_NS, LiveJudge

MS = 1_000_000


AHEAD = 180  # the beam at 0 rad (angle_min is -pi)


def _scan(nearest: float, beam: int = AHEAD) -> Scan:
    """The scan a clean driver publishes with one return, `nearest` m away on `beam`."""
    spec = preset("gazebo")
    truth = np.full(spec.samples, np.inf)
    truth[beam] = nearest
    return build_profile([]).emit(truth, spec, np.random.default_rng(0), stamp=0.0)


def _judge() -> tuple[LiveJudge, RunResult]:
    result = RunResult("single_wall", "live", 0, 0.5, "clean")
    return LiveJudge(Oracle(0.5), result), result


def test_answers_are_judged_against_the_scan_published_before_them() -> None:
    judge, result = _judge()
    judge.sent(0, 0.0, (0.0, 0.0, 0.0), _scan(1.2), 1000 * MS)
    judge.heard("status", "obstacle 1.20 m at 0.00 rad", 1010 * MS)
    judge.heard("warning", False, 1011 * MS)
    judge.sent(1, 0.1, (0.0, 0.0, 0.0), _scan(0.3), 1100 * MS)
    judge.heard("status", "obstacle 0.30 m at 0.00 rad", 1105 * MS)
    judge.heard("warning", True, 1106 * MS)
    assert judge.settle(1100 * MS + GRACE_NS - 1) == []  # scan 0's answers may still come
    first = judge.settle(1100 * MS + GRACE_NS)
    assert [v.tick for v in first] == [0] and first[0].ok
    last = judge.settle(2000 * MS, final=True)
    assert [v.tick for v in last] == [1] and last[0].ok
    assert [r.tick for r in result.records] == [0, 1]


def test_a_scan_without_a_status_fails_and_says_so() -> None:
    judge, _ = _judge()
    judge.sent(0, 0.0, (0.0, 0.0, 0.0), _scan(1.2), 1000 * MS)
    judge.sent(1, 0.1, (0.0, 0.0, 0.0), _scan(1.2), 1100 * MS)
    (verdict,) = judge.settle(1100 * MS + GRACE_NS)
    assert not verdict.ok
    assert "no status" in verdict.failures[0]


def test_a_wrong_answer_is_explained_as_run_explains_it() -> None:
    judge, _ = _judge()
    judge.sent(0, 0.0, (0.0, 0.0, 0.0), _scan(1.0, beam=90), 1000 * MS)
    angle = np.degrees(preset("gazebo").angle_min + 90 * preset("gazebo").angle_increment)
    judge.heard("status", f"obstacle 1.00 m at {angle:.2f} rad", 1010 * MS)
    judge.heard("warning", False, 1011 * MS)
    (verdict,) = judge.settle(1200 * MS, final=True)
    assert not verdict.ok
    assert "degrees" in " ".join(verdict.failures)


def test_answers_before_the_first_scan_are_counted_not_judged() -> None:
    judge, result = _judge()
    judge.heard("status", "early", 5 * MS)
    assert judge.unmatched == 1 and not result.records
