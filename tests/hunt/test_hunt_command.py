"""`fossbot-hil hunt` end to end: real nodes over Fast DDS on the embedded Dask cluster.

Each planted mistake shows only in narrow conditions (a nearest return near the
threshold, an angle_min of -pi, the driver's 0.0 for no return, nothing in range);
the hunt must find it within 150 runs, shrink it to at most one obstacle, and
leave a scenario file that fails again through `fossbot-hil run`. A correct node
must survive 100 runs.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from harness.audit.mutants import mutant_command
from harness.cli import main
from harness.scenario.files import load_scenario_file

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(400)]


def hunt(out: Path, *options: str) -> int:
    return main(["hunt", "--out", str(out), *options])


def summary(out: Path) -> dict:
    return json.loads((out / "hunt.json").read_text())


# mistake -> the hunt's seed. A hunt is the same for a seed, so each test is too; any seed
# finds each within the 150 runs (benchmarks/hunt_rate.py: seeds 0-4 needed 4 to 88 runs),
# and these need few, which keeps the suite short.
PLANTED = {
    "rounded_before_comparing": 3,
    "angle_without_angle_min": 0,
    "zero_as_obstacle": 0,
    "crash_when_nothing_in_range": 0,
}


@pytest.mark.parametrize("mistake", PLANTED)
def test_hunt_finds_shrinks_and_reproduces_a_planted_mistake(mistake: str, tmp_path: Path) -> None:
    out = tmp_path / "hunt"
    seed = str(PLANTED[mistake])
    node = mutant_command(mistake)
    # The shrink budget is cut to 10 runs (default 60), to keep the suite short: the
    # simplifications that matter come first (fault, convention, obstacle, motion, length).
    options = ["--budget", "150", "--workers", "1", "--seed", seed, "--shrink-budget", "10"]
    code = hunt(out, "--node", node, *options)
    assert code == 1
    found = summary(out)
    assert found["found"] and found["found_at_run"] <= 150
    assert found["reproduced"] is True, (out / "explanation.txt").read_text()
    scenario = load_scenario_file(out / "counterexample.yaml")  # a valid scenario file
    assert len(scenario.obstacles) <= 1
    kinds = found["counterexample"]["kinds"].split(",")
    explanation = (out / "explanation.txt").read_text()
    assert "0 of 1 scenario passed" in explanation
    assert (out / "counterexample.mcap").stat().st_size > 0
    assert (out / "counterexample.png").stat().st_size > 0
    command = (out / "reproduce.sh").read_text().splitlines()[-1]
    assert command.startswith("fossbot-hil run ") and mistake in command
    if mistake == "rounded_before_comparing":  # within 0.1 m of the threshold band
        assert kinds == ["warning"] and len(scenario.obstacles) == 1
        nearest = _nearest_return(explanation)
        assert abs(nearest - scenario.threshold) < 0.1
    elif mistake == "angle_without_angle_min":
        assert "angle" in kinds and scenario.lidar.preset == "gazebo"  # angle_min -pi
    elif mistake == "zero_as_obstacle":
        assert "driver_zero" in scenario.faults
    else:  # nothing in range: no obstacle, or none within range_max
        assert kinds == ["error"]
        assert not scenario.obstacles or "no valid return" in explanation


def test_hunt_finds_nothing_wrong_with_a_correct_node_in_100_runs(tmp_path: Path, capsys) -> None:
    out = tmp_path / "hunt"
    code = hunt(out, "--node", mutant_command("correct"), "--budget", "100", "--workers", "2")
    assert code == 0
    said_out = capsys.readouterr().out
    assert "no failing scenario in 100 runs (" in said_out and "stopped by the budget" in said_out
    said = summary(out)
    assert not said["found"] and said["runs"] == 100 and said["stopped_by"] == "budget"
    assert said["problems"] == 0 and not said["flaky"], json.dumps(said["flaky"], indent=1)
    assert not (out / "counterexample.yaml").exists()
    with (out / "runs.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 100 and {row["failed"] for row in rows} == {"False"}


def test_the_same_seed_makes_the_same_hunt_on_one_worker_or_two(tmp_path: Path) -> None:
    """The inprocess link (the reference solution): runs.csv is the same but for times."""
    tables = []
    for workers in ("1", "2"):
        out = tmp_path / workers
        code = hunt(
            out, "--link", "inprocess", "--budget", "8", "--seed", "7", "--workers", workers
        )
        assert code == 0
        with (out / "runs.csv").open() as handle:
            tables.append(
                [{k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(handle)]
            )
    assert len(tables[0]) == 8 and tables[0] == tables[1]  # two batches, the second told


@pytest.mark.parametrize(
    ("options", "said"),
    [
        (["--budget", "0"], "budget"),
        (["--link", "rplidar"], "--link rplidar"),
        (["--domain-id", "5"], "--domain-id"),
        (["--node", "/no/such/node"], "/no/such/node"),
        (["--batch", "x"], "batch"),
    ],
)
def test_usage_errors_exit_2_in_one_line(
    options: list[str], said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert hunt(tmp_path / "hunt", *options) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and len(err.splitlines()) == 1


def test_an_out_that_is_a_file_is_a_usage_error(tmp_path: Path, capsys) -> None:
    taken = tmp_path / "taken"
    taken.write_text("mine")
    assert hunt(taken, "--link", "inprocess", "--budget", "1") == 2
    assert "not a folder" in capsys.readouterr().err and taken.read_text() == "mine"


def _nearest_return(explanation: str) -> float:
    """The nearest valid return the first failing tick's explanation names."""
    words = explanation.split("nearest valid return ", 1)[1]
    return float(words.split(" m", 1)[0])
