"""One hunt run, as a Dask task: a candidate scenario through the node, assessed.

It carries all it needs and starts the node in its own process group and
ROS domain on any worker, bounded by the scenario's own deadlines.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, replace
from typing import Any

from harness.hunt.margin import Assessment
from harness.hunt.space import Candidate
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings
from harness.safe_text import clip

FAILURE_CHARS = 500  # of the first failure kept
SOURCE = "hunt candidate"


@dataclass(frozen=True)
class Outcome:
    """A candidate's run: its assessment and what it cost."""

    candidate: Candidate
    assessment: Assessment | None  # None: the run could not be made (`problem`)
    wall_s: float
    problem: str = ""  # the harness's own trouble, not the node's: no verdict either way

    def as_row(self) -> dict[str, Any]:
        row: dict[str, Any] = {**self.candidate.as_dict()}
        if self.assessment is not None:
            row.update(asdict(self.assessment))
            row["kinds"] = ",".join(self.assessment.kinds)
        row["problem"] = self.problem
        row["wall_s"] = round(self.wall_s, 3)
        return row


def scenario_of(candidate: Candidate, *, seed: int, description: str = "") -> Any:
    """The checked scenario `candidate` stands for (a usage error names what is wrong)."""
    from harness.hunt.space import robot_footprint, scenario_document
    from harness.scenario.files import checked_scenario

    words = description or f"hunt: {candidate.describe()}"
    document = scenario_document(candidate, robot_footprint(), description=words[:200], seed=seed)
    return checked_scenario(document, source=SOURCE)


def run_candidate(
    candidate: Candidate, seed: int, link_name: str, options: LinkOptions, judged: RunSettings
) -> Outcome:
    """Run `candidate` through a fresh link and assess it; a run the harness could not
    make is an outcome with a `problem`, never a counterexample."""
    from harness.hunt.margin import assess
    from harness.runner.scenario_run import run

    started = time.perf_counter()
    try:
        scenario = scenario_of(candidate, seed=seed)
        result = run(scenario, link_name, options, replace(judged, seed=seed))
    except Exception as err:  # noqa: BLE001 - the outcome says what went wrong
        problem = clip(f"{type(err).__name__}: {err}", FAILURE_CHARS)
        return Outcome(candidate, None, time.perf_counter() - started, problem)
    assessment = assess(result)
    said = assessment.first_failure.removeprefix(f"{SOURCE}: ")  # the file has its own name
    assessment = replace(assessment, first_failure=clip(said, FAILURE_CHARS))
    return Outcome(candidate, assessment, time.perf_counter() - started)
