"""The `fossbot-hil` command line: exit codes and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from command_line import fossbot_hil

from harness.cli import main

STUDENTS = Path(__file__).parent / "student_functions.py"


def test_list_names_every_shipped_scenario(capsys: pytest.CaptureFixture[str]) -> None:
    """`list` shows names and descriptions."""
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in ("approach_wall", "drive_past_10m", "out_of_range"):
        assert name in out
    assert all(line == line.rstrip() for line in out.splitlines()), "trailing spaces"


def test_run_inprocess_passes() -> None:
    """A real process: the reference logic passes a lab scenario, exit 0."""
    done = fossbot_hil("run", "approach_wall", "--link", "inprocess", timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "approach_wall" in done.stdout and "PASS" in done.stdout


def test_run_buggy_processor_exits_1_with_explanation() -> None:
    """A failing node exits 1 and the first failure is explained."""
    done = fossbot_hil(
        "run",
        "drive_past_10m",
        "--link",
        "inprocess",
        "--processor",
        f"{STUDENTS}:min_over_raw_ranges",
        timeout=120,
    )
    assert done.returncode == 1
    assert "drive_past_10m: t=" in done.stdout and "expected no obstacle" in done.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["run", "no_such_scenario"], "unknown scenario 'no_such_scenario'"),
        (["run", "--seed", "x"], "seed must be a whole number"),
        (["run", "--threshold", "-1"], "threshold must be a positive number"),
        (["run", "--threshold", "nan"], "threshold must be a positive number"),
        (["run", "--link", "carrier_pigeon"], "unknown link 'carrier_pigeon'"),
        (["run", "--link", "inprocess", "--processor", "nothing"], "expected MODULE:FUNCTION"),
        (["run", "--link", "inprocess", "--processor", "nope:fn"], "cannot import"),
        (["run", "--processor", "nope:fn"], "--processor needs --link inprocess"),
        (["run", "--link", "inprocess", "--node", "python3 x.py"], "--node needs a link that"),
        (["run", "--faults", "sparkles"], "sparkles"),
        (["run", "--status-regex", "(unclosed"], "regex"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_usage_errors_exit_2_with_one_line(
    args: list[str], needle: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Bad input: exit 2, one line on stderr, no traceback."""
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("fossbot-hil: error: ")
    assert needle in err


def test_malformed_scenario_file_exits_2_naming_file_and_field(tmp_path: Path) -> None:
    """The real command on a broken file: exit 2, `file: field: reason`, nothing else."""
    bad = tmp_path / "broken.yaml"
    bad.write_text(
        "description: x\nmotion:\n  segments:\n    - linear: fast\n      until: {duration: 1}\n"
    )
    done = fossbot_hil("run", str(bad), "--link", "inprocess", timeout=120)
    assert done.returncode == 2
    assert done.stderr.strip() == (
        f"fossbot-hil: error: {bad}: motion.segments[0].linear: "
        "Input should be a valid number, unable to parse string as a number"
    )
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_help_shows_the_topic_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    """--scan-topic, --status-topic and --warning-topic say their defaults in --help."""
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    for default in ("(default /scan;", "(default /lidar_status)", "(default /obstacle_warning)"):
        assert default in help_text


def test_a_reused_out_folder_says_what_it_cleared_and_times_the_run(tmp_path: Path) -> None:
    """summary.json's wall_s is the command's wall time (the terminal's total row), each
    scenario's own time beside it; a second run into the folder says what it removed."""
    out = tmp_path / "report"
    scenarios = ("approach_wall", "out_of_range")
    first = fossbot_hil("run", *scenarios, "--link", "inprocess", "--out", str(out))
    assert first.returncode == 0, first.stdout + first.stderr
    summary = json.loads((out / "summary.json").read_text())
    total_row = next(line for line in first.stdout.splitlines() if line.startswith("total"))
    assert float(total_row.split()[-1]) == pytest.approx(summary["wall_s"], abs=0.006)
    assert summary["wall_s"] >= max(e["total_s"] for e in summary["scenarios"])
    assert all(e["wall_s"] <= e["total_s"] for e in summary["scenarios"])
    listed = sum(v is not None for e in summary["scenarios"] for v in e["files"].values())
    second = fossbot_hil("run", "approach_wall", "--link", "inprocess", "--out", str(out))
    assert second.returncode == 0, second.stdout + second.stderr
    assert f"--out: removed {listed} scenario files of the run before" in second.stdout
    assert not list((out / "scenarios").glob("out_of_range*"))
