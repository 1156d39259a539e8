"""One audit unit as a Dask task: a mutant (or the correct control) through the suite.

The task runs ``harness.audit.worker`` as a bounded child process (as
``grade`` runs a student's suite), so the nodes start by fork from the
child's main thread and a mutant that crashes or hangs ends only its unit.
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

__all__ = ["AuditConfig", "AuditUnit", "UnitResult", "run_unit"]

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
    units_dir: Path  # one folder per unit: job.json, results.json, run.log

    @property
    def unit_timeout(self) -> float:
        return SECONDS_PER_SCENARIO * len(self.scenarios) * len(self.seeds) + 30.0


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
    wall_s: float = 0.0

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


def run_unit(unit: AuditUnit, config: AuditConfig, cancel: Any = None) -> UnitResult:
    """Run `unit` through every seed's suite in a bounded worker process; never raises for
    what the node does (that is the unit's result)."""
    from harness.audit.worker import write_job
    from harness.grading.process import run_bounded

    folder = config.units_dir / unit.name
    folder.mkdir(parents=True, exist_ok=True)
    results = folder / "results.json"
    results.unlink(missing_ok=True)
    job = write_job(
        folder / "job.json",
        command=unit.command,
        scenarios=list(config.scenario_refs),
        link=config.link,
        options=config.options,
        settings=config.settings,
        seeds=list(config.seeds),
        coverage=unit.name == CONTROL,
        results=results,
    )
    finished = run_bounded(
        [sys.executable, "-m", "harness.audit.worker", str(job)],
        log=folder / "run.log",
        timeout=config.unit_timeout,
        max_log_bytes=MAX_LOG_BYTES,
        cwd=folder,
        cancel=cancel or threading.Event(),
    )
    try:
        data = json.loads(results.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {}
    outcome = UnitResult(unit.name, list(data.get("runs", [])), wall_s=finished.wall_s)
    if data.get("error"):
        outcome.error = str(data["error"])
    elif not data.get("finished"):
        if finished.timed_out:
            outcome.error = f"stopped after {config.unit_timeout:g} s"
        elif finished.cancelled:
            outcome.error = "interrupted"
        else:
            code = finished.returncode
            outcome.error = finished.start_error or f"the audit worker ended (exit code {code})"
    return outcome
