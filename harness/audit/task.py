"""A batch of audit units as a Dask task: mutants (or the correct control) through the suite.

It runs ``harness.audit.worker`` as a bounded child process (as ``grade``
does a student's), whose main thread forks the nodes from one warm Python
per batch. Each unit's failure is its own; should the worker die, the unit
it was running gets the reason and the rest run in a fresh worker.
"""

from __future__ import annotations

import json
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from harness.audit.mutants import CONTROL
from harness.judge.verdicts import RunVerdict
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings

__all__ = ["AuditConfig", "AuditUnit", "UnitResult", "run_batch"]

MAX_LOG_BYTES = 8 * 1024 * 1024
SECONDS_PER_SCENARIO = 90.0  # a unit's bound: each suite's runs end at their own deadlines
STOP_MARGIN_S = 60.0  # past its units' bounds, for the worker to start and to stop a unit


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
    seconds_per_scenario: float = SECONDS_PER_SCENARIO  # of a unit's bound, per run

    @property
    def unit_timeout(self) -> float:
        """One unit's bound from its start: generous, as each run ends at its own deadlines."""
        return self.seconds_per_scenario * len(self.scenarios) * len(self.seeds)

    def batch_timeout(self, units: int) -> float:
        """A worker process's bound, should it not stop a unit past the unit's own."""
        return self.unit_timeout * units + STOP_MARGIN_S


@dataclass(frozen=True)
class AuditUnit:
    """A node to run through the suite: a mutant, or the correct control."""

    name: str
    command: str
    # A kill needs only a scenario's first failed tick: a mutant's runs may end there
    # (RunSettings.stop_at_first_failure); the control's never do (it must pass whole).
    stop_at_first_failure: bool = False

    def overrides(self) -> dict[str, dict[str, Any]]:
        """What this unit runs with beyond the audit's RunSettings (job.json)."""
        return {"settings": {"stop_at_first_failure": self.stop_at_first_failure}}


@dataclass
class UnitResult:
    """What one unit's suites gave: per seed, each scenario's verdict and first failure."""

    name: str
    runs: list[dict[str, Any]] = field(default_factory=list)  # results.json's "runs"
    error: str | None = None  # the unit did not finish: why

    def verdicts(self, scenario: str) -> list[str]:
        """The scenario's verdict in each seed's suite, in seed order ("NOT RUN" if absent).
        A node that never came up is an ERROR, as in any run: a mistake can be why (a node
        that ignores the scan topic parameter never subscribes to the harness's scans)."""
        found = []
        for run in self.runs:
            entry = next((e for e in run["results"] if e["scenario"] == scenario), None)
            found.append(entry["verdict"] if entry else RunVerdict.NOT_RUN.value)
        return found

    def first_failure(self, scenario: str) -> str:
        for run in self.runs:
            for entry in run["results"]:
                if entry["scenario"] == scenario and entry["verdict"] != RunVerdict.PASS:
                    return str(entry.get("first_failure") or "")
        return ""


def run_batch(
    batch: tuple[AuditUnit, ...], config: AuditConfig, number: int, cancel: Any = None
) -> list[UnitResult]:
    """Run each unit of `batch` through every seed's suite in a bounded worker process
    (another for the units a dead one had not started); never raises for what a node does
    (that is its unit's result)."""
    folder = config.units_dir / f"batch-{number}"
    folder.mkdir(parents=True, exist_ok=True)
    stop = cancel or threading.Event()
    done: dict[str, UnitResult] = {}
    waiting = list(batch)
    while waiting:
        if done and stop.is_set():  # interrupted between two workers
            done.update((unit.name, UnitResult(unit.name, error="interrupted")) for unit in waiting)
            break
        units, why, final = _run_worker(waiting, config, folder, stop)
        for unit in waiting:
            entry = units.get(unit.name)
            if entry is not None:  # started: its runs, and why it did not finish
                error = entry.get("error") or (None if entry.get("done") else why)
                done[unit.name] = UnitResult(unit.name, list(entry.get("runs", [])), error)
        left = [unit for unit in waiting if unit.name not in done]
        if final or len(left) == len(waiting):  # nothing more would run in another worker
            done.update((unit.name, UnitResult(unit.name, error=why)) for unit in left)
            break
        waiting = left
    return [done[unit.name] for unit in batch]


def _run_worker(
    units: list[AuditUnit], config: AuditConfig, folder: Path, stop: Any
) -> tuple[dict[str, Any], str, bool]:
    """One worker process through `units`: each started unit's entry by name, why the
    worker stopped where it did, and whether that holds for every unit not started (an
    interruption, a scenario the worker cannot resolve)."""
    from harness.audit.worker import write_job
    from harness.grading.process import run_bounded

    results = folder / "results.json"
    results.unlink(missing_ok=True)
    names = [unit.name for unit in units]
    job = write_job(
        folder / "job.json",
        commands={unit.name: unit.command for unit in units},
        overrides={unit.name: unit.overrides() for unit in units},
        scenarios=list(config.scenario_refs),
        link=config.link,
        options=config.options,
        settings=config.settings,
        seeds=list(config.seeds),
        coverage=CONTROL if CONTROL in names else None,
        results=results,
        unit_timeout=config.unit_timeout,
    )
    timeout = config.batch_timeout(len(units))
    finished = run_bounded(
        [sys.executable, "-m", "harness.audit.worker", str(job)],
        log=folder / "run.log",
        timeout=timeout,
        max_log_bytes=MAX_LOG_BYTES,
        cwd=folder,
        cancel=stop,
    )
    try:
        data = json.loads(results.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {}
    if not isinstance(data, dict):
        data = {}
    units_seen = data.get("units", {})
    if not isinstance(units_seen, dict):
        units_seen = {}
    if data.get("error"):  # the worker said why it stopped (a scenario it cannot resolve)
        return units_seen, str(data["error"]), True
    if finished.cancelled:
        return units_seen, "interrupted", True
    if finished.timed_out:
        why = f"its worker was stopped after {timeout:g} s"
    elif finished.flooded:
        why = f"its worker wrote more than {MAX_LOG_BYTES // (1024 * 1024)} MB of output"
    else:
        why = finished.start_error or f"its worker ended (exit code {finished.returncode})"
    return units_seen, f"{why} (see {folder / 'run.log'})", False
