"""`fossbot-hil run --baseline FILE [--fail-on regression]` as a user types it."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil

from harness import __version__

TESTS = Path(__file__).resolve().parents[1]
DEGREES_NODE = f"{sys.executable} {TESTS / 'ros' / 'student_node.py'} angle_in_degrees"
DEGREES_FUNCTION = f"{TESTS / 'student_functions.py'}:angle_in_degrees"


@pytest.mark.ros
@pytest.mark.timeout(180)
def test_degrees_node_regresses_against_the_reference(tmp_path: Path) -> None:
    """Reference baseline, then a node answering in degrees: reported as a regression and
    failing with --fail-on regression; against its own baseline the same node passes."""
    base, now = tmp_path / "base", tmp_path / "now"
    done = fossbot_hil("run", "approach_wall", "--out", str(base), timeout=150)
    assert done.returncode == 0, done.stdout + done.stderr

    strict = ["--node", DEGREES_NODE, "--fail-on", "regression"]
    done = fossbot_hil("run", "approach_wall", *strict, "--baseline", str(base / "summary.json"),
                       "--out", str(now), timeout=150)  # fmt: skip
    assert done.returncode == 1, done.stdout + done.stderr
    assert "regressed  approach_wall  clean   PASS  FAIL" in done.stdout
    assert "failing, and not known from the baseline: approach_wall [clean] (regressed)" in (
        done.stdout
    )
    summary = json.loads((now / "summary.json").read_text())
    assert summary["scenarios"][0]["change"] == "regressed"
    assert summary["baseline"]["ok"] is False and summary["baseline"]["counts"]["regressed"] == 1
    assert '<span class="regressed">regressed</span>' in (now / "index.html").read_text()

    done = fossbot_hil("run", "approach_wall", *strict, "--baseline", str(now), timeout=150)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 regressed, 0 fixed, 1 still failing" in done.stdout
    assert "looks like degrees" in done.stdout  # the failure is still shown in full


def test_known_failure_still_exits_1_by_default(tmp_path: Path) -> None:
    """Without --fail-on, a baseline only adds the comparison: any failure exits 1.
    A baseline from another harness version is named as such."""
    baseline = tmp_path / "summary.json"
    known = {"scenario": "approach_wall", "verdict": "FAIL", "ok": False, "faults": "clean",
             "link": "inprocess", "threshold": 0.5, "seed": 0}  # fmt: skip
    baseline.write_text(json.dumps({"harness": "0.0.1", "scenarios": [known]}))
    done = fossbot_hil("run", "approach_wall", "--link", "inprocess", "--processor",
                       DEGREES_FUNCTION, "--baseline", str(baseline))  # fmt: skip
    assert done.returncode == 1, done.stdout + done.stderr
    assert f"the baseline comes from fossbot-hil 0.0.1, this is {__version__}" in done.stdout
    assert "1 still failing" in done.stdout
    assert "no regression: every failure is known from the baseline" in done.stdout


def test_a_run_with_no_failure_says_nothing_fails(tmp_path: Path) -> None:
    """Against a baseline, a run where everything passed says so, not 'every failure is
    known'."""
    base = tmp_path / "base"
    inprocess = ["approach_wall", "--link", "inprocess"]
    assert fossbot_hil("run", *inprocess, "--out", str(base)).returncode == 0
    done = fossbot_hil("run", *inprocess, "--baseline", str(base), "--fail-on", "regression")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "no regression: nothing fails" in done.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--baseline", "{tmp}/nowhere.json"], "nowhere.json: no such file"),
        (["--baseline", "{tmp}/bad.json"], "bad.json: not JSON"),
        (["--fail-on", "regression"], "--fail-on regression needs --baseline FILE"),
    ],
)
def test_bad_baseline_exits_2_before_running(tmp_path: Path, args: list[str], needle: str) -> None:
    """A missing or malformed baseline, or --fail-on without one: one line, exit 2,
    before the report folder exists."""
    (tmp_path / "bad.json").write_text("[1, 2")
    args = [a.format(tmp=tmp_path) for a in args]
    out = tmp_path / "report"
    done = fossbot_hil("run", "approach_wall", "--out", str(out), *args, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    assert needle in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()
