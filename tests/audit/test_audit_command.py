"""`fossbot-hil audit` as an instructor runs it: real mutant nodes over a real ROS 2 graph,
on the embedded Dask cluster, with small budgets (two mistakes, two short scenarios, one
worker). The full library through the default suite is in the issue notes and
docs/audit.md: it takes about 200 s on 2 cores."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from command_line import COMMAND
from short_scenarios import WALL_AHEAD

from harness.audit import MUTANTS
from harness.cli import main

# drive_past_10m in 1.5 s: its warning must clear (the audit runs every mistake through
# every scenario, once per seed).
DRIVE_AWAY = """\
description: Start near a wall and drive 1 m away from it (drive_past_10m, short).
lidar:
  preset: gazebo
obstacles:
  - type: wall
    start: [-0.4, -3.0]
    end: [-0.4, 3.0]
    thickness: 0.1
motion:
  segments:
    - linear: 1.0
      until: {distance: 1.0}
    - until: {duration: 0.5}
threshold: 0.5
"""


def scenario_file(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return str(path)


def audit(tmp_path: Path, *args: str, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    """The command in `tmp_path`, with its own cache folder there, on one worker."""
    env = {**os.environ, "FOSSBOT_HIL_CACHE_DIR": str(tmp_path / "cache")}
    return subprocess.run(
        [*COMMAND, "audit", *args, "--workers", "1", "--out", str(tmp_path / "audit")],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=tmp_path,
        env=env,
    )


@pytest.mark.parametrize(
    "args, says",
    [
        (["--mutant", "degrees"], "unknown mutant 'degrees'"),
        (["--mutant", "correct"], "'correct' is the control, not a mutant"),
        (["--mutant", "centimetres,centimetres"], "--mutant: a mistake is named twice"),
        (["--repeat", "0"], "--repeat: "),
        (["--link", "inprocess"], "--link inprocess: audit runs nodes"),
        (["no_such_scenario"], "no_such_scenario"),
        (["--threshold", "-1"], "--threshold"),
    ],
)
def test_usage_errors_exit_2_in_one_line(
    args: list[str], says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["audit", *args]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], err
    assert "Traceback" not in err


def test_list_names_every_mistake_in_the_library(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", "--list"]) == 0
    out = capsys.readouterr().out
    listed = [line.split()[0] for line in out.splitlines() if line.strip()]
    assert listed == [m.name for m in MUTANTS] and len(listed) >= 20


@pytest.mark.ros
@pytest.mark.timeout(240)
def test_json_gives_kills_survivors_coverage_and_flips(tmp_path: Path) -> None:
    """wall_ahead + drive_away, twice each: drive_away's warning must clear, so it kills
    the latched warning; neither delivers a NaN beside a valid return, so the node that
    does not filter NaN survives, and the coverage says why."""
    done = audit(
        tmp_path,
        scenario_file(tmp_path, "wall_ahead", WALL_AHEAD),
        scenario_file(tmp_path, "drive_away", DRIVE_AWAY),
        "--mutant",
        "warning_latched,nan_not_filtered",
        "--repeat",
        "2",
        "--json",
    )
    assert done.returncode == 1, done.stdout + done.stderr  # a mistake survived
    data = json.loads(done.stdout)
    assert {m["name"]: m["killed_by"] for m in data["mutants"]} == {
        "warning_latched": ["drive_away"],
        "nan_not_filtered": [],
    }
    assert data["survivors"] == ["nan_not_filtered"]
    assert data["flips"] == [] and data["seeds"] == [None, 1001]
    nan = data["coverage"]["cases"]["nan"]
    assert nan == {"beside_valid": 0, "without_valid": 0}, data["coverage"]
    assert data["coverage"]["warning_clears"] >= 1
    assert any("NaN beside a valid return" in gap for gap in data["coverage_gaps"])
    assert json.loads((tmp_path / "audit" / "audit.json").read_text())["survivors"] == [
        "nan_not_filtered"
    ]
    assert "warning True" in data["mutants"][0]["first_failure"], data["mutants"][0]
    assert list((tmp_path / "cache" / "audit").glob("*.json")), "not kept for grade"


@pytest.mark.ros
@pytest.mark.timeout(240)
def test_a_suite_where_no_warning_clears_lets_the_latched_warning_pass(tmp_path: Path) -> None:
    """wall_ahead (an approach) and out_of_range never go from near to far: the matrix
    names the latched warning a survivor, with the kind of scenario that would catch it."""
    done = audit(
        tmp_path,
        scenario_file(tmp_path, "wall_ahead", WALL_AHEAD),
        "out_of_range",
        "--mutant",
        "warning_latched,angle_in_degrees",
    )
    assert done.returncode == 1, done.stdout + done.stderr
    out = done.stdout
    assert "mistakes no scenario catches, and what would catch them:" in out, out
    latched = next(line for line in out.splitlines() if line.startswith("  warning_latched:"))
    assert "moves away" in latched, latched
    assert "score: the suite catches 1 of 2 mistakes" in out
    assert "times a due warning stopped being due later in its run: 0" in out
