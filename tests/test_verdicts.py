"""One verdict type for every command and report: its words, and how a run gets one."""

from __future__ import annotations

import json

from gazebo_scans import make_scan

from harness.campaign.task import RunVerdict as CampaignVerdict
from harness.judge.answers import Answers
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.judge.verdicts import RunVerdict, verdict_of


def test_a_verdict_is_its_word_in_text_json_and_tables() -> None:
    assert [str(v) for v in RunVerdict] == ["PASS", "FAIL", "ERROR", "NOT RUN"]
    assert json.dumps([RunVerdict.NOT_RUN]) == '["NOT RUN"]'
    assert f"{RunVerdict.FAIL:<6}|" == "FAIL  |"
    assert RunVerdict.PASS == "PASS" and RunVerdict.PASS.passed
    assert CampaignVerdict is RunVerdict  # the campaign's rows say it the same way


def test_a_verdict_read_back_from_a_table() -> None:
    assert RunVerdict.read("passed") is RunVerdict.PASS
    assert RunVerdict.read(" FAILED ") is RunVerdict.FAIL
    assert RunVerdict.read("NOT RUN") is RunVerdict.NOT_RUN
    assert RunVerdict.read("") is RunVerdict.ERROR
    assert RunVerdict.read("what?") is RunVerdict.ERROR


def test_a_run_that_ended_on_a_silent_node_is_a_fail_everywhere() -> None:
    """The campaign took ERROR from `result.error`, the reports from `broken`: a node
    silent from its first scan on ended the run (an error) but is judged FAIL."""
    scan = make_scan({180: 1.0})
    silent = Answers(timed_out=True, waited=1.0, problem="node ... published nothing", silent=True)
    verdict = Oracle(0.5).judge(0, 0.0, scan, silent)
    result = RunResult("s", "ros2", 0, 0.5, "clean", error="t=0.00 s tick 0: silent")
    result.records.append(TickRecord(0, 0.0, 0.0, 0.0, 0.0, scan, silent, verdict))
    assert verdict_of(result) is RunVerdict.FAIL
    assert verdict_of(RunResult("s", "ros2", 0, 0.5, "clean", error="broke")) is RunVerdict.ERROR
    assert verdict_of(RunResult("s", "ros2", 0, 0.5, "clean")) is RunVerdict.PASS
    skipped = RunResult("s", "ros2", 0, 0.5, "clean", error="not run", not_run=True)
    assert verdict_of(skipped) is RunVerdict.NOT_RUN
