"""Verdicts at the speed real nodes run: suites longer than every fixed bound.

A correct node that takes 30 ms or 0.3 s a scan passes however long the suite
runs; a node silent on its first scan fails at that tick and the suite goes
on; a scenario whose node cannot start keeps what was judged before it. Each
run here lasts longer than the harness's fixed bounds (10 s for a node to be
reported started, counted from when its link is awaited), which a suite of
fast nodes never reaches.
"""

from __future__ import annotations

import json
import re
import stat
import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil
from short_scenarios import NEAR_WALL, nothing_in_range

from harness.nodes.process import START_WAIT_S
from harness.ros.domain import reserve_domain

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

STUDENT = Path(__file__).parent / "student_node.py"


def student(variant: str) -> str:
    return f"{sys.executable} {STUDENT} {variant}"


def rows(stdout: str) -> dict[str, str]:
    """scenario -> verdict, from the run's table."""
    found = {}
    for line in stdout.splitlines():
        words = line.split()
        for verdict in ("PASS", "FAIL", "ERROR", "NOT RUN"):
            if len(words) > 4 and f" {verdict} " in f" {line} " and words[1] == "ros2":
                found[words[0]] = verdict
    return found


def total_seconds(stdout: str) -> float:
    """The table's total time: the command's wall time."""
    found = re.search(r"^total\s.*?(\d+\.\d+)\s*$", stdout, re.MULTILINE)
    assert found is not None, stdout
    return float(found.group(1))


def short_suite(folder: Path, count: int) -> list[str]:
    """`count` short scenario files, walls and nothing in range in turn."""
    paths = []
    for i in range(count):
        path = folder / f"s{i}_{'clear' if i % 2 else 'wall'}.yaml"
        path.write_text(nothing_in_range() if i % 2 else NEAR_WALL)
        paths.append(str(path))
    return paths


def test_a_correct_node_at_30_ms_a_scan_passes_the_default_suite() -> None:
    """30 ms a scan (a node that logs every scan): the default suite's 544 scans take
    longer than the start bound, and every link started ahead is judged, not refused."""
    done = fossbot_hil("run", "--node", student("correct"), "--param", "delay_s:=0.03")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "7 of 7 scenarios passed" in done.stdout
    total = total_seconds(done.stdout)
    assert total > START_WAIT_S, done.stdout  # the run met the bound it used to fail on


def test_a_correct_node_at_a_third_of_a_second_a_scan_passes_a_long_suite(
    tmp_path: Path,
) -> None:
    """0.3 s a scan, under the 1 s deadline: slow, right, PASS in every scenario."""
    paths = short_suite(tmp_path, 6)
    done = fossbot_hil("run", *paths, "--node", student("correct"), "--param", "delay_s:=0.3")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "6 of 6 scenarios passed" in done.stdout
    total = total_seconds(done.stdout)
    assert total > START_WAIT_S, done.stdout


def test_a_node_silent_on_its_first_scan_fails_there_and_the_suite_goes_on(
    tmp_path: Path,
) -> None:
    """Silent when nothing is in range, from its first scan on: that scenario FAILs at
    tick 0 (the node started, so it is no start-up error) and the next ones run."""
    clear, wall, clear_again = short_suite(tmp_path, 4)[1:]
    done = fossbot_hil(
        "run",
        clear,
        wall,
        clear_again,
        *("--node", student("silent_when_clear"), "--ready-timeout", "3"),
    )
    assert done.returncode == 1, done.stdout + done.stderr
    found = rows(done.stdout)
    assert list(found.values()) == ["FAIL", "PASS", "FAIL"], done.stdout
    assert "tick 0: " in done.stdout
    assert "a status is expected when nothing is in range too" in done.stdout
    assert "NOT RUN" not in done.stdout and "cannot start" not in done.stderr


def test_a_suite_whose_third_node_cannot_start_keeps_what_was_judged(tmp_path: Path) -> None:
    """The node's program stops being runnable after two scenarios (here it makes itself
    not executable): the first two keep their verdicts, the third says why it could not
    start, the rest are not run, and the report is written."""
    runs = tmp_path / "runs"
    runs.mkdir()
    node = tmp_path / "node.sh"
    node.write_text(
        "#!/bin/sh\n"
        f'n=$(ls "{runs}" | wc -l); touch "{runs}/run$n"\n'
        f'[ "$n" -ge 1 ] && chmod -x "$0"\n'  # the second start is the last that can
        f'exec {sys.executable} {STUDENT} correct "$@"\n'
    )
    node.chmod(node.stat().st_mode | stat.S_IXUSR)
    paths = short_suite(tmp_path, 4)
    with reserve_domain(None) as domain:  # held, so no other run takes it; released to us
        domain_id = domain.domain_id
    out = tmp_path / "report"
    done = fossbot_hil(
        "run", *paths, "--node", str(node), "--domain-id", str(domain_id), "--out", str(out)
    )
    assert done.returncode == 1, done.stdout + done.stderr
    found = rows(done.stdout)
    assert list(found.values()) == ["PASS", "PASS", "ERROR", "NOT RUN"], done.stdout
    assert "could not start" in done.stdout and "not executable" in done.stdout, done.stdout
    summary = json.loads((out / "summary.json").read_text())
    verdicts = [entry["verdict"] for entry in summary["scenarios"]]
    assert verdicts == ["PASS", "PASS", "ERROR", "NOT RUN"]


def test_a_run_that_ends_at_its_first_failure_does_not_wait_for_the_late_answer() -> None:
    """With stop_at_first_failure (the audit's mistakes), a missed deadline ends the run:
    the link does not wait on (catch up) for the late answer, which only kept it from
    being taken for the next scan's, and no next scan goes."""
    from harness.links.base import LinkOptions
    from harness.runner.scenario_run import run
    from harness.runner.settings import RunSettings
    from harness.scenario.files import resolve_scenario

    slow_second = (f"{student('correct')} --ros-args -p delay_s:=1.5 -p slow_scan:=2",)
    options = LinkOptions(node=slow_second[0], scan_timeout=0.5)
    settings = RunSettings(stop_at_first_failure=True)
    result = run(resolve_scenario("approach_wall"), "ros2", options, settings)
    assert result.stopped_early and len(result.records) == 2, result.first_failure
    explanation = result.records[-1].verdict.explanation
    assert "no status within the deadline (0.50 s)" in explanation
    assert "it came after" not in explanation  # the catch-up would have heard it at 1.5 s
