"""Link faults as users name them: scenario files, the command line, pytest (no ROS)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from command_line import fossbot_hil

from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.record.reader import read_scans
from harness.runner.scenario_run import run
from harness.runner.settings import RunSettings
from harness.scenario.files import load_scenario_file, resolve_scenario

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(120)

STUDENTS = Path(__file__).parent / "student_functions.py"
SCENARIO = """\
name: lossy_wall
description: Approach a wall over a lossy, drifting link.
motion:
  segments:
    - {linear: 0.2, until: {distance: 0.8}}
faults:
  - noisy
  - lossy_link
  - {type: reorder, rate: 0.2}
  - {type: delay, mean: 0.001, jitter: 0.001}
  - {type: rate_drift, min_hz: 3.3, max_hz: 6.7}
  - {type: stale_stamps, rate: 0.2, age: 0.5}
obstacles:
  - {type: wall, start: [1.0, -1.0], end: [1.0, 1.0]}
"""


def inprocess(scenario, processor: str | None = None, **settings) -> object:
    return run(scenario, "inprocess", LinkOptions(processor=processor), RunSettings(**settings))


def test_a_scenario_file_names_link_faults_and_the_reference_passes(tmp_path: Path) -> None:
    """Every delivery kind happens, each tick says how it travelled, and all verdicts hold."""
    path = tmp_path / "lossy_wall.yaml"
    path.write_text(SCENARIO)
    result = inprocess(load_scenario_file(path), seed=4)
    assert result.ok, result.first_failure
    kinds = [r.delivery.kind for r in result.records]
    assert {"sent", "dropped", "duplicate", "reordered"} <= set(kinds)
    assert all(not r.answers.statuses for r in result.records if r.delivery.kind == "dropped")
    assert any(r.delivery.stamp_age_s == 0.5 for r in result.records)
    periods = {round(r.scan.scan_time, 6) for r in result.records}
    assert len(periods) > 3 and all(1 / 6.7 - 1e-9 <= p <= 1 / 3.3 + 1e-9 for p in periods)


def test_a_wrong_node_is_still_caught_under_link_faults() -> None:
    """Faults never turn a wrong answer into a pass: the inverted Bool fails, in words."""
    scenario = resolve_scenario("approach_wall")
    faults = ["lossy_link", "drifting_rate", "stale_stamps"]
    result = inprocess(scenario, f"{STUDENTS}:inverted_bool", faults=faults)
    assert not result.ok
    assert "expected warning" in (result.first_failure or "")


def test_a_faster_drift_counts_against_the_run_length(tmp_path: Path) -> None:
    """A run too long at the drift's highest rate is refused when the file loads."""
    path = tmp_path / "long.yaml"
    text = SCENARIO.replace("{linear: 0.2, until: {distance: 0.8}}", "{until: {duration: 590}}")
    path.write_text(text.replace("max_hz: 6.7", "max_hz: 20"))
    with pytest.raises(ConfigError, match=r"scans at 20 Hz\); at most"):
        load_scenario_file(path)


def test_the_command_line_takes_inline_link_faults_and_reports_deliveries(tmp_path: Path) -> None:
    """`--faults lossy_link,delay(...)`: exit 0, and the JSON names each tick's delivery."""
    out = tmp_path / "out"
    done = fossbot_hil(
        "run", "approach_wall", "--link", "inprocess", "--seed", "2", "--out", str(out),
        "--faults", "lossy_link,delay(mean=0.002,jitter=0.001)",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    ticks = json.loads((out / "scenarios" / "approach_wall.json").read_text())["records"]
    kinds = {t["delivery"]["kind"] for t in ticks}
    assert {"sent", "dropped"} <= kinds
    assert all(
        0.001 <= t["delivery"]["delay_s"] <= 0.003 for t in ticks if t["delivery"]["kind"] == "sent"
    )
    # The recording holds the scans the node got: a dropped one was never injected.
    delivered = sum(1 for t in ticks if t["delivery"]["kind"] != "dropped")
    assert len(read_scans(out / "scenarios" / "approach_wall.mcap").scans) == delivered


@pytest.mark.parametrize(
    ("faults", "words"),
    [
        ("drop(rate=2)", "--faults: faults[0].rate: must be in [0, 1], got 2"),
        ("delay(mean=0.1", "expected KIND(KEY=VALUE,...)"),
        ("delay(mean=3)", "delay mean must be in [0, 2] s, got 3"),
        ("rate_drift(min_hz=7)", "rate_drift min_hz (7) is above max_hz (6.7)"),
        ("delay(mean=0.1,mean=0.2)", "'delay(mean=0.1,mean=0.2)': mean given twice"),
        ("delay(mean=nan)", "faults[0].mean: must be a number, got 'nan'"),
        ("line_drops(rate=0.01)", "need a serial link (rplidar or ldlidar), not 'inprocess'"),
    ],
)
def test_bad_link_faults_exit_2_with_one_line(faults: str, words: str) -> None:
    """Each mistake is one line naming it, exit 2, no traceback."""
    done = fossbot_hil("run", "approach_wall", "--link", "inprocess", "--faults", faults)
    assert done.returncode == 2
    assert words in done.stderr and len(done.stderr.strip().splitlines()) == 1


def test_pytest_users_name_link_faults_like_scan_faults(pytester: pytest.Pytester) -> None:
    """hil.run(..., faults="...") and the hil_scenarios marker take link faults too."""
    pytester.makepyfile(
        """
        import pytest

        def test_lossy(hil):
            result = hil.run("approach_wall", faults="noisy,lossy_link,rate_drift(max_hz=5)")
            assert result.ok, result.explanation
            assert any(r.delivery.kind == "dropped" for r in result.records)

        @pytest.mark.hil_scenarios("approach_wall", faults=["slow_link", "drop(rate=0.3)"])
        def test_marked(hil, hil_case):
            assert hil.run(hil_case).ok
        """
    )
    result = pytester.runpytest("--hil-link", "inprocess", "-v")
    result.assert_outcomes(passed=3)
    result.stdout.fnmatch_lines(["*test_marked?approach_wall-drop(rate=0.3)?*PASSED*"])


def test_replay_puts_link_faults_on_recorded_scans(tmp_path: Path) -> None:
    """`replay --faults lossy_link` drops and repeats recorded scans; scan faults are refused."""
    out = tmp_path / "out"
    assert (
        fossbot_hil("run", "approach_wall", "--link", "inprocess", "--out", str(out)).returncode
        == 0
    )
    recording = out / "scenarios" / "approach_wall.mcap"
    again = tmp_path / "again.mcap"
    done = fossbot_hil(
        "replay", str(recording), "--link", "inprocess", "--faults", "lossy_link",
        "--seed", "5", "--record", str(again),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert len(read_scans(again).scans) != len(read_scans(recording).scans)
    refused = fossbot_hil("replay", str(recording), "--link", "inprocess", "--faults", "noisy")
    assert refused.returncode == 2
    assert "only link faults apply" in refused.stderr
