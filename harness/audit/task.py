"""A batch of audit units as a Dask task: mutants (or the correct control) through the suite.

The task runs ``harness.audit.worker`` as a bounded child process (as
``grade`` runs a student's suite), so the nodes start by fork from the
child's main thread (its warm Python started once for the batch, not once
per mutant), and a mutant that crashes or hangs ends only its own runs.
Everything it needs travels with it, so any worker can take it.
"""

from __future__ import annotations

import json
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from harness.audit.mutants import CONTROL
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

__all__ = ["AuditConfig", "AuditUnit", "UnitResult", "run_batch"]

MAX_LOG_BYTES = 8 * 1024 * 1024
SECONDS_PER_SCENARIO = 90.0  # a unit's bound: each suite's runs end at their own deadlines


@dataclass(frozen=True)
class AuditConfig:
    """What every unit of an audit runs with."""

    scenarios: tuple[str, ...]  # names, in matrix order
    scenario_refs: tuple[str, ...]  # what the worker resolves (names or absolute paths)
    link: str
    options: LinkOptions
    settings: RunSettings
    seeds: tuple[int | None, ...]  # one suite per seed; None: each scenario's own
    units_dir: Path  # one folder per batch: job.json, results.json, run.log

    def batch_timeout(self, units: int) -> float:
        """A batch's bound: generous per scenario run, as each run ends at its deadlines."""
        return SECONDS_PER_SCENARIO * len(self.scenarios) * len(self.seeds) * units + 30.0


@dataclass(frozen=True)
class AuditUnit:
    """A node to run through the suite: a mutant, or the correct control."""

    name: str
    command: str


@dataclass
class UnitResult:
    """What one unit's suites gave: per seed, each scenario's verdict and first failure."""

    name: str
    runs: list[dict[str, Any]] = field(default_factory=list)  # results.json's "runs"
    error: str | None = None  # the unit did not finish: why

    def verdicts(self, scenario: str) -> list[str]:
        """The scenario's verdict in each seed's suite, in seed order ("NOT RUN" if absent)."""
        found = []
        for run in self.runs:
            entry = next((e for e in run["results"] if e["scenario"] == scenario), None)
            found.append(entry["verdict"] if entry else "NOT RUN")
        return found

    def first_failure(self, scenario: str) -> str:
        for run in self.runs:
            for entry in run["results"]:
                if entry["scenario"] == scenario and entry["verdict"] != "PASS":
                    return str(entry.get("first_failure") or "")
        return ""


def run_batch(
    batch: tuple[AuditUnit, ...], config: AuditConfig, number: int, cancel: Any = None
) -> list[UnitResult]:
    """Run each unit of `batch` through every seed's suite in one bounded worker process;
    never raises for what a node does (that is its unit's result)."""
    from harness.audit.worker import write_job
    from harness.grading.process import run_bounded

    folder = config.units_dir / f"batch-{number}"
    folder.mkdir(parents=True, exist_ok=True)
    results = folder / "results.json"
    results.unlink(missing_ok=True)
    names = [unit.name for unit in batch]
    job = write_job(
        folder / "job.json",
        commands={unit.name: unit.command for unit in batch},
        scenarios=list(config.scenario_refs),
        link=config.link,
        options=config.options,
        settings=config.settings,
        seeds=list(config.seeds),
        coverage=CONTROL if CONTROL in names else None,
        results=results,
    )
    timeout = config.batch_timeout(len(batch))
    finished = run_bounded(
        [sys.executable, "-m", "harness.audit.worker", str(job)],
        log=folder / "run.log",
        timeout=timeout,
        max_log_bytes=MAX_LOG_BYTES,
        cwd=folder,
        cancel=cancel or threading.Event(),
    )
    try:
        data = json.loads(results.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {}
    if not isinstance(data, dict):
        data = {}
    units = data.get("units", {})
    if data.get("error"):  # the worker said why it stopped (a scenario it cannot resolve)
        why = str(data["error"])
    elif finished.timed_out:
        why = f"stopped after {timeout:g} s"
    elif finished.cancelled:
        why = "interrupted"
    else:
        why = finished.start_error or f"the audit worker ended (exit code {finished.returncode})"
    outcomes = []
    for name in names:
        unit = units.get(name, {})
        outcome = UnitResult(name, list(unit.get("runs", [])))
        if not unit.get("finished"):
            outcome.error = why
        outcomes.append(outcome)
    return outcomes
