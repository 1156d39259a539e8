"""Run the whole shipped suite again and again through one link; report any flake.

A flake is a round whose exit code or per-scenario verdicts differ from
the others: the harness is deterministic, so every round must agree.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

ROUND_TIMEOUT_S = 600


@dataclass(frozen=True)
class Round:
    index: int
    exit_code: int
    wall_s: float
    verdicts: dict[str, str]  # scenario -> PASS/FAIL/ERROR/NOT RUN
    first_failure: str

    @property
    def line(self) -> str:
        failed = {k: v for k, v in self.verdicts.items() if v != "PASS"}
        what = f"exit {self.exit_code}" + (f", {failed}: {self.first_failure}" if failed else "")
        return f"round {self.index}: {self.wall_s:.1f} s, {what}"


def _one_round(index: int, link: str, out: Path) -> Round:
    started = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, "-m", "harness.cli", "run", "--link", link, "--out", str(out)],
            capture_output=True,
            text=True,
            timeout=ROUND_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired:  # a hang is a flake too; the child is killed
        return Round(index, -1, time.perf_counter() - started, {}, "hung: no result in time")
    wall = time.perf_counter() - started
    summary = out / "summary.json"
    if not summary.exists():
        return Round(index, done.returncode, wall, {}, (done.stderr or done.stdout)[-300:])
    data = json.loads(summary.read_text())
    verdicts = {s["scenario"]: s["verdict"] for s in data["scenarios"]}
    failures = [s.get("first_failure") or "" for s in data["scenarios"] if s["verdict"] != "PASS"]
    return Round(index, done.returncode, wall, verdicts, failures[0] if failures else "")


@pytest.mark.timeout(0)  # each round is bounded by ROUND_TIMEOUT_S instead
def test_suite_soak(soak_link: str, soak_runs: int, tmp_path: Path) -> None:
    """Every round of the reference node's suite passes; the summary gives the numbers."""
    rounds = [_one_round(i, soak_link, tmp_path / f"round{i}") for i in range(soak_runs)]
    bad = [r for r in rounds if r.exit_code != 0]
    slowest = max(rounds, key=lambda r: r.wall_s)
    walls = sorted(r.wall_s for r in rounds)
    print(
        f"\nsoak {soak_link}: {len(rounds)} rounds, {len(bad)} failed; wall median "
        f"{walls[len(walls) // 2]:.1f} s, slowest round {slowest.index} {slowest.wall_s:.1f} s"
    )
    for r in bad:
        print("  " + r.line)
    assert not bad, "\n".join(r.line for r in bad)
