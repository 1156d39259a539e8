"""A batch of mutants through the audited suite, each once per seed.

``python -m harness.audit.worker JOB``: its own process, so its main thread
may fork the nodes from a warm Python (a Dask worker's thread may not).
JOB (``write_job``) says what to run; ``results.json`` is rewritten
atomically as each unit starts and after each suite, so a batch stopped at
its limit still tells what it judged. A unit past its bound is stopped as
SIGTERM stops a suite, one whose node is a usage error gets that as its
error, and the next runs; only an unresolved scenario or the command's
SIGTERM ends the batch.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from harness.atomic_write import write_atomically
from harness.errors import ConfigError, one_line
from harness.safe_text import clip

__all__ = ["FAILURE_CHARS", "UnitClock", "write_job"]

FAILURE_CHARS = 600  # of each scenario's first failure kept in results.json


def write_job(path: Path, *, options: Any, settings: Any, results: Path, **job: Any) -> Path:
    """Write a job file: LinkOptions and RunSettings as their fields, the rest as given (the
    node `commands` and their `overrides` by unit, `scenarios`, `link`, `seeds`, the unit
    whose `coverage` is kept, `unit_timeout`), as `run_job` reads them."""
    job |= {"options": asdict(options), "settings": asdict(settings), "results": str(results)}
    return write_atomically(path, json.dumps(job, indent=2).encode())


def _entry(result: Any) -> dict[str, Any]:
    from harness.judge.verdicts import verdict_of

    failure = result.first_failure or result.error or ""
    return {
        "scenario": result.scenario,
        "verdict": verdict_of(result),
        "first_failure": clip(failure, FAILURE_CHARS),
        "not_started": result.not_started,
        "ticks": len(result.records),
        "stopped_early": result.stopped_early,  # ended at its first failed tick
    }


class UnitClock:
    """One unit's time bound, counted from its start.

    Past it the main thread gets a SIGTERM's KeyboardInterrupt, so the suite
    stops the unit's nodes and the worker goes on; a SIGTERM from outside is
    told apart (no unit was overdue).
    """

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.overdue = False  # the running unit had its time
        self._lock = threading.Lock()
        self._running = False
        self._sent = False  # its SIGTERM is on its way to the handler

    def install(self) -> None:
        """SIGTERM raises KeyboardInterrupt in the main thread, but not the clock's own, late."""

        def handler(signum: int, frame: object) -> None:
            with self._lock:
                late = self._sent and not self._running
                self._sent = False
            if not late:
                raise KeyboardInterrupt

        signal.signal(signal.SIGTERM, handler)

    @contextmanager
    def bound(self) -> Iterator[None]:
        """Time the unit run inside the block."""
        with self._lock:
            self.overdue, self._running = False, True
        timer = threading.Timer(self.seconds, self._expire)
        timer.daemon = True
        timer.start()
        try:
            yield
        finally:
            with self._lock:
                self._running = False
            timer.cancel()

    def _expire(self) -> None:
        with self._lock:
            if not self._running:
                return
            self.overdue = self._sent = True
        os.kill(os.getpid(), signal.SIGTERM)


def run_job(job: dict[str, Any], clock: UnitClock | None = None) -> int:
    """Run each unit's suite once per seed; results.json tells the outcome (each unit's
    runs, whether it is done, and its error), the exit code only if the worker broke."""
    from harness.grading.worker import link_options_from, run_settings_from
    from harness.scenario.files import resolve_scenario

    results_path = Path(job["results"])
    state: dict[str, Any] = {"units": {}, "running": None, "error": None}

    def write() -> None:
        write_atomically(results_path, json.dumps(state, indent=2).encode())

    clock = clock or UnitClock(float(job["unit_timeout"]))
    options = link_options_from(job["options"])
    base = run_settings_from(job["settings"])
    try:
        chosen = [resolve_scenario(ref) for ref in job["scenarios"]]
    except ConfigError as err:  # the same for every unit: the batch says it once
        state["error"] = str(err)
        write()
        return 0
    for name, command in job["commands"].items():
        unit: dict[str, Any] = {"runs": [], "done": False, "error": None}
        state["units"][name], state["running"] = unit, name
        write()
        started = time.monotonic()
        own = job.get("overrides", {}).get(name, {})
        node = replace(options, node=command)
        settings = replace(base, **own.get("settings", {}))
        try:
            with clock.bound():
                _run_unit(unit, name, chosen, job, node, settings, write)
        except KeyboardInterrupt:
            if not clock.overdue:  # SIGTERM from the command: links closed, nodes stopped
                unit["error"] = "stopped"
                write()
                return 1
            unit["error"] = f"stopped after {clock.seconds:g} s (its bound)"
        except ConfigError as err:  # e.g. its node cannot start for want of rclpy
            unit["error"] = str(err)
        except Exception as err:  # noqa: BLE001 - the harness's error, but this unit's only
            traceback.print_exc()  # into run.log
            unit["error"] = f"the audit failed on it: {type(err).__name__}: {one_line(err)}"
        took = time.monotonic() - started
        print(f"{name}: {unit['error'] or 'done'} ({took:.1f} s)", flush=True)
        unit["done"], state["running"] = True, None
        write()
    return 0


def _run_unit(
    unit: dict[str, Any],
    name: str,
    chosen: list[Any],
    job: dict[str, Any],
    node: Any,
    base: Any,
    write: Any,
) -> None:
    """One unit's suite once per seed into `unit`, written after each."""
    from harness.judge.reading_coverage import coverage_of, gaps
    from harness.runner.suite import run_suite

    for seed in job["seeds"]:
        results = run_suite(chosen, job["link"], node, replace(base, seed=seed))
        run: dict[str, Any] = {"seed": seed, "results": [_entry(r) for r in results]}
        if job.get("coverage") == name:
            coverage = coverage_of(results)
            run["coverage"], run["coverage_gaps"] = coverage.as_dict(), gaps(coverage)
        unit["runs"].append(run)
        write()


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m harness.audit.worker JOB.json", file=sys.stderr)
        return 2
    from harness.runner.frame_memo import remember_frames

    job = json.loads(Path(argv[0]).read_text(encoding="utf-8"))
    remember_frames()  # a batch runs the suite once a mutant: its scenarios simulated once
    clock = UnitClock(float(job["unit_timeout"]))
    clock.install()
    return run_job(job, clock)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
