"""`run --watch` and `run --failed-first` as a user runs them, on the inprocess link.

No ROS here: the processing function is a file the test edits, loaded anew
for each scenario, so these show the loop itself (what is re-run, in which
order, a save during a run, Ctrl-C, usage errors) in a few seconds. The
same loop over ROS 2, with a node script and a colcon workspace, is in
test_watch_node.py and test_watch_workspace.py.
"""

from __future__ import annotations

import json
import re
import shutil
import signal
from pathlib import Path

import pytest
from command_line import fossbot_hil
from watch_process import save, save_by_rename, verdict_lines

from harness.scenario.files import shipped_dir

pytestmark = pytest.mark.timeout(120)

# A processing function as a student writes it; THRESHOLD = None uses the threshold
# given, a number is the hard-coded threshold bug (obstacle_at_side's is 0.3 m, not 0.5).
PROCESSOR = """\
import math
import time

THRESHOLD = {threshold}
SECONDS_PER_SCAN = {delay}


def process(scan, threshold):
    time.sleep(SECONDS_PER_SCAN)
    valid = [r for r in scan.ranges if math.isfinite(r) and scan.range_min <= r <= scan.range_max]
    if not valid:
        return "No obstacle", False
    best = min(valid)
    angle = scan.angle_min + list(scan.ranges).index(best) * scan.angle_increment
    return f"Obstacle at {{best:.3f}} m, {{angle:.3f}} rad", best < (THRESHOLD or threshold)
"""
RIGHT, HARD_CODED = "None", "0.5"
SCENARIOS = ("approach_wall", "obstacle_at_side")


def processor(folder: Path, threshold: str = RIGHT, delay: float = 0.0) -> Path:
    path = folder / "proc.py"
    save(path, PROCESSOR.format(threshold=threshold, delay=delay))
    return path


def test_a_fix_reruns_the_failed_scenario_first(tmp_path: Path, start_watch) -> None:
    """Run, save a fix, see the failed scenario first and every scenario pass; Ctrl-C: 130."""
    processor(tmp_path, HARD_CODED)
    watch = start_watch(*SCENARIOS, "--link", "inprocess", "--processor", "proc.py:process")
    first = watch.expect(r"scenarios? passed")
    assert first[-1].startswith("1 of 2 scenarios passed"), first
    assert verdict_lines(first) == list(SCENARIOS)
    assert any(line.startswith("FAIL    obstacle_at_side") for line in first), first
    watch.expect("watching for changes")
    processor(tmp_path, RIGHT)
    second = watch.expect(r"scenarios? passed")
    assert second[0].startswith("run 2: changed proc.py; failed last time first: obstacle_at_side")
    assert verdict_lines(second) == ["obstacle_at_side", "approach_wall"]
    assert re.match(r"2 of 2 scenarios passed \(\d+\.\d\d s since the change\)", second[-1])
    assert watch.interrupt() == 130
    assert watch.lines[-1] == "stopped by SIGINT"
    assert "Traceback" not in watch.stderr()


def test_a_save_during_a_run_is_run_next(tmp_path: Path, start_watch) -> None:
    """A file saved while a run goes starts the next run at once, after this one."""
    processor(tmp_path)  # the first run only has to end: at full speed
    watch = start_watch(
        "approach_wall", "drive_past_10m", "--link", "inprocess", "--processor", "proc.py:process"
    )
    watch.expect("watching for changes")
    processor(tmp_path, delay=0.026)  # from here drive_past_10m's 136 scans take over 3 s
    watch.expect(r"^run 2: changed proc.py")
    watch.expect(r"^PASS +approach_wall")  # drive_past_10m runs for seconds more
    # drive_past_10m may be loading proc.py this very moment: a save in place could
    # hand it half a file; a rename hands it the old text or the new one.
    save_by_rename(tmp_path / "proc.py", PROCESSOR.format(threshold=RIGHT, delay=0.025))
    rest = watch.expect(r"^run 3: changed proc.py")
    assert rest[0].startswith("PASS    drive_past_10m") and rest[1].startswith("2 of 2"), rest
    assert not any("watching for changes" in line for line in rest), rest  # run 3 came at once
    watch.expect(r"2 of 2 scenarios passed")
    assert watch.interrupt(signal.SIGTERM) == 143


def test_ctrl_c_while_waiting_ends_cleanly(tmp_path: Path, start_watch) -> None:
    """Ctrl-C between runs: one line, exit 130, no traceback."""
    processor(tmp_path)
    watch = start_watch("approach_wall", "--link", "inprocess", "--processor", "proc.py:process")
    watch.expect("watching for changes")
    assert watch.interrupt() == 130
    assert watch.lines[-1] == "stopped by SIGINT" and "Traceback" not in watch.stderr()


def test_a_scenario_file_edit_reruns_and_a_broken_one_waits(tmp_path: Path, start_watch) -> None:
    """A scenario file given by path is watched with the bundled function: a change re-runs,
    a half-edited file is shown as one line and the next save runs again."""
    scenario = tmp_path / "mine.yaml"
    shutil.copy(shipped_dir() / "approach_wall.yaml", scenario)
    good = scenario.read_text()
    watch = start_watch(str(scenario), "--link", "inprocess")
    assert watch.expect("^watching ")[0] == f"watching scenario file {scenario.resolve()}"
    watch.expect(r"1 of 1 scenario passed")
    save(scenario, good + "\nnot: [valid\n")
    problem = watch.expect(r"^not run: ")[-1]
    assert "mine.yaml" in problem, problem
    watch.expect("watching for changes")
    save(scenario, good)
    assert watch.expect(r"scenarios? passed")[-1].startswith("1 of 1 scenario passed")
    assert watch.interrupt() == 130


def test_the_reports_are_rewritten_after_each_run(tmp_path: Path, start_watch) -> None:
    """--out and --junit-xml hold the last run, written once its verdicts are shown."""
    processor(tmp_path, HARD_CODED)
    watch = start_watch(
        *SCENARIOS, "--link", "inprocess", "--processor", "proc.py:process",
        "--out", "report", "--junit-xml", "junit.xml",
    )  # fmt: skip
    watch.expect(r"^junit: junit.xml")
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["passed"] == 1
    processor(tmp_path, RIGHT)
    watch.expect(r"2 of 2 scenarios passed")
    watch.expect(r"^junit: junit.xml")
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["passed"] == 2
    assert [s["scenario"] for s in summary["scenarios"]] == ["obstacle_at_side", "approach_wall"]
    assert 'failures="0"' in (tmp_path / "junit.xml").read_text()
    assert watch.interrupt() == 130


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ([], "--watch: nothing to watch: the bundled node is not yours to edit"),
        (["--link", "inprocess"], "the bundled processing function is not yours"),
        (["--node", "python3 missing.py"], "no such script missing.py"),
        (["--node", "ros2 run pkg exe"], "'ros2' is a program, not a file of yours"),
        (["--gui"], "--gui cannot go with --watch"),
        (["--out", "r", "--animate"], "--animate cannot go with --watch"),
        (["--baseline", "summary.json"], "--baseline cannot go with --watch"),
        (["--fail-on", "regression"], "--fail-on regression cannot go with --watch"),
    ],
)
def test_watch_usage_errors(tmp_path: Path, args: list[str], message: str) -> None:
    """Nothing to watch, or an option that has no place in the loop: exit 2, one line."""
    done = fossbot_hil("run", "approach_wall", "--watch", *args, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.count("\n") == 1 and message in done.stderr, done.stderr
    assert "Traceback" not in done.stderr


def table_order(stdout: str) -> list[str]:
    return [line.split()[0] for line in stdout.splitlines() if line.split()[1:2] == ["inprocess"]]


def test_failed_first_without_watch_uses_the_last_run(tmp_path: Path, monkeypatch) -> None:
    """`run --failed-first` puts what failed when this node last ran here first."""
    monkeypatch.chdir(tmp_path)
    processor(tmp_path, HARD_CODED)
    args = ("run", *SCENARIOS, "--link", "inprocess", "--processor", "proc.py:process")
    done = fossbot_hil(*args, "--failed-first", timeout=60)
    assert done.returncode == 1
    assert "--failed-first: none of these failed last time" in done.stdout
    assert table_order(done.stdout) == list(SCENARIOS)
    done = fossbot_hil(*args, "--failed-first", timeout=60)
    assert "--failed-first: 1 failed last time, run first: obstacle_at_side" in done.stdout
    assert table_order(done.stdout) == ["obstacle_at_side", "approach_wall"]
    processor(tmp_path, RIGHT)
    assert fossbot_hil(*args, timeout=60).returncode == 0  # a plain run keeps its verdicts too
    done = fossbot_hil(*args, "--failed-first", timeout=60)
    assert table_order(done.stdout) == list(SCENARIOS), done.stdout
