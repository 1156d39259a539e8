"""`run --watch --node "python3 node.py"`: a student's script over real ROS 2, edited.

The script is tests/ros/student_node.py with its bug written in, as a
student's one file; each node it starts appends its pid to a file, so the
test can tell that Ctrl-C left none running.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import pytest
from child_process import alive
from watch_process import save, student_variant, verdict_lines

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]

SCENARIOS = ("approach_wall", "obstacle_at_side")  # the hard-coded threshold fails the second


def test_saving_a_fix_reruns_failed_first_then_ctrl_c_reaps(
    tmp_path: Path, start_watch, cache_home: Path
) -> None:
    """Run, save the fix, the failed scenario runs first and all pass; Ctrl-C: exit 130 and
    no node (nor anything else the command started) left running."""
    node, pids = tmp_path / "node.py", tmp_path / "pids"
    save(node, student_variant("threshold_hard_coded", pids=pids))
    watch = start_watch(*SCENARIOS, "--node", f"{sys.executable} node.py")
    watched = watch.expect("^Ctrl-C to stop")
    assert watched[0] == f"watching node.py and the .py files beside it in {tmp_path.resolve()}"
    first = watch.expect(r"scenarios? passed")
    assert first[-1].startswith("1 of 2 scenarios passed"), first
    assert verdict_lines(first) == list(SCENARIOS)
    watch.expect("watching for changes")

    save(node, student_variant("correct", pids=pids))
    second = watch.expect(r"scenarios? passed")
    assert second[0].startswith("run 2: changed node.py; failed last time first: obstacle_at_side")
    assert verdict_lines(second) == ["obstacle_at_side", "approach_wall"]
    assert second[-1].startswith("2 of 2 scenarios passed (")

    started = {int(pid) for pid in pids.read_text().split()}
    assert len(started) == 4  # a fresh node per scenario and run
    assert watch.interrupt() == 130
    assert watch.lines[-1] == "stopped by SIGINT" and "Traceback" not in watch.stderr()
    left = sorted(pid for pid in started | watch.seen if alive(pid))
    assert not left, f"still running after Ctrl-C: {left}"
    (cache,) = (cache_home / "last-run").glob("*.json")
    verdicts = json.loads(cache.read_text())["verdicts"]
    assert verdicts == {"approach_wall": "passed", "obstacle_at_side": "passed"}


def test_ctrl_c_during_a_run_reaps_the_node(tmp_path: Path, start_watch) -> None:
    """Ctrl-C while a node answers: the run stops, the node is reaped, exit 130."""
    node, pids = tmp_path / "node.py", tmp_path / "pids"
    save(node, student_variant("correct", pids=pids))
    watch = start_watch(
        "approach_wall", "--node", f"{sys.executable} node.py", "--param", "delay_s:=0.05"
    )  # about 5 s of answers
    watch.expect(r"^run 1: ")
    deadline = time.monotonic() + 30
    while not (pids.is_file() and pids.read_text().strip()):  # the node has started
        assert time.monotonic() < deadline and watch.popen.poll() is None, watch.lines
        time.sleep(0.05)
    code = watch.interrupt()
    assert code == 130 and "Traceback" not in watch.stderr()
    started = {int(pid) for pid in pids.read_text().split()}
    assert not [pid for pid in started | watch.seen if alive(pid)]
