"""A batch of mutants through the audited suite, each once per seed:
``python -m harness.audit.worker JOB``.

Its own process, as a student's suite in ``grade`` is: its main thread may
start the nodes by fork from a warm Python (a Dask worker's thread may not;
the warm Python is started once for the batch), and a node that takes its
process down takes only this batch with it. JOB is a JSON file
(``write_job``) naming each mutant's node command, the scenarios, the link,
the LinkOptions and RunSettings fields, the seeds, and where
``results.json`` goes; it is rewritten (atomically) after every suite, so a
batch stopped at its time limit still tells what it judged.
"""

from __future__ import annotations

import json
import sys
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from harness.atomic_write import write_atomically
from harness.errors import ConfigError
from harness.safe_text import clip

__all__ = ["FAILURE_CHARS", "write_job"]

FAILURE_CHARS = 600  # of each scenario's first failure kept in results.json


def write_job(
    path: Path,
    *,
    commands: dict[str, str],
    scenarios: list[str],
    link: str,
    options: Any,
    settings: Any,
    seeds: list[int | None],
    coverage: str | None,
    results: Path,
) -> Path:
    """Write a job file for this worker: each mutant's node command by name, LinkOptions and
    RunSettings as their fields, and which unit's runs give the reading coverage."""
    job = {
        "commands": commands,
        "scenarios": scenarios,
        "link": link,
        "options": asdict(options),
        "settings": asdict(settings),
        "seeds": seeds,
        "coverage": coverage,
        "results": str(results),
    }
    return write_atomically(path, json.dumps(job, indent=2).encode())


def _entry(result: Any) -> dict[str, Any]:
    from harness.report.summary import verdict_of

    failure = result.first_failure or result.error or ""
    return {
        "scenario": result.scenario,
        "verdict": verdict_of(result),
        "first_failure": clip(failure, FAILURE_CHARS),
        "ticks": len(result.records),
    }


def run_job(job: dict[str, Any]) -> int:
    """Run each unit's suite once per seed; results.json tells the outcome, the exit code
    only if the worker itself broke."""
    from harness.grading.worker import link_options_from, run_settings_from
    from harness.judge.reading_coverage import coverage_of, gaps
    from harness.runner.suite import run_suite
    from harness.scenario.files import resolve_scenario

    results_path = Path(job["results"])
    units: dict[str, dict[str, Any]] = {}

    def write(error: str | None = None) -> None:
        data = {"units": units, "error": error}  # a unit not finished: `error` says why
        write_atomically(results_path, json.dumps(data, indent=2).encode())

    options = link_options_from(job["options"])
    base = run_settings_from(job["settings"])
    try:
        chosen = [resolve_scenario(ref) for ref in job["scenarios"]]
        for name, command in job["commands"].items():
            unit: dict[str, Any] = {"runs": [], "finished": False}
            units[name] = unit
            node = replace(options, node=command)
            for seed in job["seeds"]:
                results = run_suite(chosen, job["link"], node, replace(base, seed=seed))
                run: dict[str, Any] = {"seed": seed, "results": [_entry(r) for r in results]}
                if job.get("coverage") == name:
                    coverage = coverage_of(results)
                    run["coverage"], run["coverage_gaps"] = coverage.as_dict(), gaps(coverage)
                unit["runs"].append(run)
                write()
            unit["finished"] = True
            write()
    except ConfigError as err:
        write(str(err))
        return 0
    except KeyboardInterrupt:  # SIGTERM from the command: links closed, nodes stopped
        write("stopped")
        return 1
    return 0


def main(argv: list[str]) -> int:
    from harness.grading.worker import interrupt_on_sigterm

    if len(argv) != 1:
        print("usage: python -m harness.audit.worker JOB.json", file=sys.stderr)
        return 2
    interrupt_on_sigterm()
    return run_job(json.loads(Path(argv[0]).read_text(encoding="utf-8")))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
