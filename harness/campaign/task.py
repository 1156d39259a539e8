"""One campaign run, as a Dask task: it runs on a worker and returns its row.

It carries all it needs, so any worker can take it; the node runs in its
own process group and ROS domain, bounded by the scenario's own deadlines,
so a hanging node ends the run, not the campaign.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import replace
from typing import Any

from harness.campaign.plan import SCENARIO_FAULTS, RunSpec
from harness.judge.verdicts import RunVerdict, verdict_of
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings
from harness.safe_text import clip, for_csv

FAILURE_CHARS = 500  # of the first failure kept in the table


def run_one(
    spec: RunSpec, link_name: str, options: LinkOptions, judged: RunSettings | None = None
) -> dict[str, Any]:
    """Run `spec` through a fresh link and return its results row; `judged` holds what
    every run of the campaign is judged with (status regex, warning rule)."""
    from harness.faults.sensor import split_fault_text
    from harness.runner.scenario_run import run
    from harness.scenario.files import resolve_scenario
    from harness.scenario.variations import varied

    started = time.perf_counter()
    try:
        scenario = varied(resolve_scenario(spec.scenario), dict(spec.variation))
        faults = None if spec.faults == SCENARIO_FAULTS else split_fault_text(spec.faults)
        settings = replace(
            judged or RunSettings(), seed=spec.seed, threshold=spec.threshold, faults=faults
        )
        result = run(scenario, link_name, options, settings)
    except Exception as err:  # a run that could not be made is a result, not a lost task
        verdict, ticks, failed = RunVerdict.ERROR, 0, 0
        failure = f"{type(err).__name__}: {err}"
    else:
        verdict = verdict_of(result)  # as `run` and every report say it
        ticks, failed = len(result.records), len(result.failed_ticks)
        failure = result.first_failure or result.error or ""
    return {
        **spec.as_row(),
        "verdict": verdict.value,
        "ticks": ticks,
        "failed_ticks": failed,
        "first_failure": for_csv(clip(failure, FAILURE_CHARS)).replace("\n", "\\n"),
        "wall_s": round(time.perf_counter() - started, 3),
        "worker": f"{socket.gethostname()}:{os.getpid()}",
    }
