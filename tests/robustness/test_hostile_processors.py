"""Whatever a processing function does, the inprocess link gives a true verdict.

The function runs in a forked child with a deadline per call
(`harness.links.processor_child`): exiting, raising a BaseException, hanging,
crashing or rewriting the scan ends as an ERROR or FAIL verdict naming the
scenario and tick, never as the harness's exit code 0, a hang, or a pass.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hostile_checks import COMMAND, marked_processes, run_command

from harness.links import LinkOptions
from harness.runner.scenario_run import run
from harness.scenario.files import resolve_scenario

HOSTILE = Path(__file__).with_name("hostile_processors.py")


def processor(name: str) -> str:
    return f"{HOSTILE}:{name}"


def run_with(name: str, scenario: str = "approach_wall", timeout: float = 1.0):
    options = LinkOptions(processor=processor(name), scan_timeout=timeout)
    return run(resolve_scenario(scenario), "inprocess", options)


@pytest.mark.parametrize(
    ("name", "phrase"),
    [
        ("exits_0", "raised SystemExit: 0"),
        ("raises_system_exit", "raised SystemExit: done"),
        ("raises_keyboard_interrupt", "raised KeyboardInterrupt"),
        ("raises_generator_exit", "raised GeneratorExit"),
        ("hard_exit_0", "ended its process: it exited with code 0"),
        ("segfaults", "ended its process: it was killed by SIGSEGV"),
        ("returns_nonsense", "returned a int, not (status, warning)"),
        ("raises_unprintable", "raised _Unprintable: (its message could not be shown)"),
    ],
)
def test_a_function_that_ends_or_raises_is_an_error_at_its_tick(name: str, phrase: str) -> None:
    """The run ends at tick 0 as an ERROR naming what the function did; no pass."""
    from harness.judge.verdicts import verdict_of

    result = run_with(name)
    assert not result.ok
    assert verdict_of(result) == "ERROR"
    assert result.error is not None and "tick 0" in result.error and phrase in result.error
    assert result.first_failure is not None
    assert result.first_failure.startswith("approach_wall: ")


def test_sys_exit_0_is_not_a_pass_on_the_command_line(tmp_path: Path) -> None:
    """Defect: `sys.exit(0)` in the function made `run --link inprocess` exit 0 with no table."""
    outcome = run_command(
        ["run", "approach_wall", "--link", "inprocess", "--processor", processor("exits_0")],
        tmp_path,
    )
    assert outcome.code == 1, outcome
    assert "Traceback" not in outcome.stderr
    assert "ERROR" in outcome.stdout
    assert "approach_wall: t=0.00 s tick 0:" in outcome.stdout
    assert "processing function raised SystemExit: 0" in outcome.stdout


@pytest.mark.parametrize("name", ["spins_forever", "sleeps_forever"])
def test_a_hang_is_an_error_within_the_deadline(name: str) -> None:
    """A function that never returns is stopped at the per-scan deadline."""
    started = time.monotonic()
    result = run_with(name, timeout=0.3)
    took = time.monotonic() - started
    assert result.error is not None and "did not return within 0.3 s" in result.error
    assert took < 10, took  # bounded by the deadline, not by the function


def test_after_a_hang_the_run_goes_on_to_the_next_scenario(tmp_path: Path) -> None:
    """The hung scenario is an ERROR; the next one runs in a fresh child and passes."""
    marker = tmp_path / "hung-once"
    outcome = run_command(
        [
            "run",
            "approach_wall",
            "out_of_range",
            "--link",
            "inprocess",
            "--timeout",
            "2",
            "--processor",
            processor("hangs_the_first_time"),
            "--out",
            "report",
        ],
        tmp_path,
        env={"FOSSBOT_TEST_MARKER": str(marker)},
    )
    assert outcome.code == 1, outcome
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    verdicts = {s["scenario"]: s["verdict"] for s in summary["scenarios"]}
    assert verdicts == {"approach_wall": "ERROR", "out_of_range": "PASS"}, verdicts
    assert "did not return within 2 s" in outcome.stdout


def test_a_function_cannot_rewrite_the_scan_it_is_judged_on() -> None:
    """Writing over `scan.ranges` changes the child's copy; the oracle judges what was sent."""
    result = run_with("hides_the_obstacle")
    assert result.failed_ticks, "a scan rewritten by the function must not be judged as sent"
    assert "expected an obstacle" in result.failed_ticks[0].verdict.explanation


def test_what_a_function_starts_is_stopped_with_it(tmp_path: Path) -> None:
    """A process the function started is killed with it (its own process group)."""
    outcome = run_command(
        [
            "run",
            "approach_wall",
            "--link",
            "inprocess",
            "--timeout",
            "0.5",
            "--processor",
            processor("starts_a_process_and_hangs"),
        ],
        tmp_path,
    )  # run_command fails the test if any process it started is still running
    assert outcome.code == 1 and "did not return within 0.5 s" in outcome.stdout


def test_what_a_function_prints_is_kept_as_diagnostics() -> None:
    """Its stdout is captured like a node's stderr, not written over the harness's terminal."""
    result = run_with("prints_escapes")
    assert result.ok
    assert "beam count 360" in result.diagnostics


def _started(tmp_path: Path, *args: str) -> tuple[subprocess.Popen[str], str]:
    marker = f"FOSSBOT_HIL_HOSTILE_TEST=interrupt-{os.getpid()}-{time.monotonic_ns()}"
    name, _, value = marker.partition("=")
    calls = {"FOSSBOT_TEST_MARKER": str(tmp_path / "calls")}
    process = subprocess.Popen(
        [*COMMAND, *args],
        cwd=tmp_path,
        env={**os.environ, **calls, name: value},
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    return process, marker


def _wait_for_calls(path: Path, count: int, process: subprocess.Popen[str]) -> None:
    """Until the function was called `count` times (the run got that far), bounded."""
    deadline = time.monotonic() + 60.0
    while not path.exists() or len(path.read_text().splitlines()) < count:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, f"not {count} calls within 60 s"
        time.sleep(0.02)


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_run_reports_what_it_judged(
    tmp_path: Path, signum: signal.Signals, code: int
) -> None:
    """Ctrl-C / SIGTERM: the table of what was judged, readable records, exit 130 / 143."""
    process, marker = _started(
        tmp_path,
        "run",
        "approach_wall",
        "drive_past_10m",
        "out_of_range",
        "--link",
        "inprocess",
        "--processor",
        processor("slow_reference"),
        "--out",
        "report",
        "--junit-xml",
        "junit.xml",
    )
    _wait_for_calls(tmp_path / "calls", 95 + 1 + 10, process)  # 10 ticks into drive_past_10m
    process.send_signal(signum)
    out, err = process.communicate(timeout=60)
    assert process.returncode == code, (out, err)
    assert "Traceback" not in err
    assert err.splitlines()[-1].startswith(f"fossbot-hil: error: interrupted by {signum.name}")
    assert "approach_wall" in out and "PASS" in out
    assert f"drive_past_10m: interrupted by {signum.name} at t=" in out
    assert "NOT RUN" in out
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    verdicts = [s["verdict"] for s in summary["scenarios"]]
    assert verdicts == ["PASS", "ERROR", "NOT RUN"], verdicts
    ET.parse(tmp_path / "junit.xml")
    ET.parse(tmp_path / "report" / "junit.xml")
    assert not marked_processes(marker)


def test_junit_calls_a_broken_run_an_error_as_the_table_does() -> None:
    """A run that broke before any wrong answer is a JUnit <error>, counted as one."""
    from harness.report.junit import junit_xml

    root = ET.fromstring(junit_xml([run_with("exits_0"), run_with("hides_the_obstacle")]))
    suite = root.find("testsuite")
    assert suite is not None and (suite.get("errors"), suite.get("failures")) == ("1", "1")
    broken, wrong = suite.findall("testcase")
    assert broken.find("error") is not None and broken.find("failure") is None
    assert wrong.find("failure") is not None
