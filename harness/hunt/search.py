"""The hunt: an optimiser's candidates run in batches, the first failure confirmed and shrunk.

Optuna's seeded TPE learns from each run's margin; after ``RESTART_AFTER``
runs without a smaller one it starts a fresh study, so one narrow valley
cannot hold it. Batches have a fixed size whatever the workers and are told
to the optimiser in order, so one seed gives one hunt on any cluster.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from harness.errors import ConfigError, HarnessError
from harness.hunt.shrink import simplifications
from harness.hunt.space import Candidate, suggest
from harness.hunt.task import Outcome

RunBatch = Callable[[list[Candidate]], list[Outcome]]
Feasible = Callable[[Candidate], "Candidate | None"]

STARTUP_TRIALS = 8  # random proposals before the sampler models the margins
RESTART_AFTER = 40  # runs without a smaller margin before a fresh study
MAX_PROPOSALS = 50  # per candidate wanted: proposals that make no scenario are skipped
MAX_PROBLEM_BATCHES = 3  # batches in a row whose runs all could not be made: stop


@dataclass(frozen=True)
class HuntPlan:
    """How long to search, and how."""

    budget: int  # search runs at most
    seconds: float | None  # wall time at most (checked between batches)
    seed: int
    batch: int  # runs proposed and told together
    shrink_budget: int  # runs shrinking may take


@dataclass
class Hunt:
    """What a hunt did and found."""

    runs: list[Outcome] = field(default_factory=list)  # the search's, in order
    found: Outcome | None = None  # the first failure that failed again
    flaky: list[Outcome] = field(default_factory=list)  # failures that did not
    confirm_runs: int = 0
    shrunk: Outcome | None = None  # the simplest version that still fails the same way
    shrink_steps: list[str] = field(default_factory=list)
    shrink_runs: int = 0
    restarts: int = 0
    elapsed_s: float = 0.0
    stopped_by: str = "budget"  # "budget", "time" or "found"

    @property
    def best(self) -> Outcome | None:
        """The passing run that came closest to failing."""
        passed = [o for o in self.runs if o.assessment and not o.assessment.failed]
        return min(passed, key=lambda o: o.assessment.margin, default=None)  # type: ignore[union-attr]

    @property
    def total_runs(self) -> int:
        return len(self.runs) + self.confirm_runs + self.shrink_runs


def optuna_module() -> Any:
    """optuna, or a usage error naming the extra that installs it."""
    try:
        import optuna
    except ImportError:
        raise ConfigError(
            "hunt needs optuna: pip install 'fossbot-hil[hunt]' (or pip install optuna)"
        ) from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    # TPE's `group` is marked experimental; the hunt pins optuna>=4, where it works as used.
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    return optuna


def hunt(
    plan: HuntPlan,
    run_batch: RunBatch,
    feasible: Feasible,
    on_batch: Callable[[Hunt], None] = lambda _: None,
) -> Hunt:
    """Search, confirm and shrink (module docstring); `on_batch` sees progress."""
    optuna = optuna_module()
    started = time.monotonic()
    result = Hunt()
    study = _study(optuna, plan.seed, 0)
    best, best_at, problem_batches = float("inf"), 0, 0
    while len(result.runs) < plan.budget:
        if plan.seconds is not None and time.monotonic() - started >= plan.seconds:
            result.stopped_by = "time"
            break
        wanted = min(plan.batch, plan.budget - len(result.runs))
        trials, candidates = _propose(optuna, study, feasible, wanted)
        outcomes = run_batch(candidates)
        problem_batches = problem_batches + 1 if all(o.assessment is None for o in outcomes) else 0
        if problem_batches >= MAX_PROBLEM_BATCHES:
            raise HarnessError(f"hunt stopped: its runs could not be made ({outcomes[0].problem})")
        for trial, outcome in zip(trials, outcomes, strict=True):
            if outcome.assessment is None:
                study.tell(trial, state=optuna.trial.TrialState.FAIL)
            else:
                study.tell(trial, outcome.assessment.margin)
        result.runs.extend(outcomes)
        on_batch(result)
        for outcome in outcomes:
            if outcome.assessment is not None and outcome.assessment.margin < best:
                best, best_at = outcome.assessment.margin, len(result.runs)
        failing = [o for o in outcomes if o.assessment is not None and o.assessment.failed]
        if failing and _confirmed(failing[0], run_batch, result):
            result.found = failing[0]
            result.stopped_by = "found"
            break
        if len(result.runs) - best_at >= RESTART_AFTER:
            result.restarts += 1
            study = _study(optuna, plan.seed, result.restarts)
            best, best_at = float("inf"), len(result.runs)
    if result.found is not None:
        _shrink(result, run_batch, plan)
    result.elapsed_s = time.monotonic() - started
    return result


def _study(optuna: Any, seed: int, restart: int) -> Any:
    """A fresh study; restart k of seed s is seeded s * 1000 + k, the same every time."""
    sampler = optuna.samplers.TPESampler(
        seed=seed * 1000 + restart,
        n_startup_trials=STARTUP_TRIALS,
        constant_liar=True,
        multivariate=True,  # distance and threshold matter together
        group=True,  # over the parameters each kind of candidate has
    )
    return optuna.create_study(direction="minimize", sampler=sampler)


def _propose(
    optuna: Any, study: Any, feasible: Feasible, count: int
) -> tuple[list[Any], list[Candidate]]:
    """`count` trials and their runnable candidates; one that makes no scenario is told failed."""
    trials, candidates = [], []
    for _ in range(count * MAX_PROPOSALS):
        if len(candidates) == count:
            break
        trial = study.ask()
        candidate = feasible(suggest(trial))
        if candidate is None:
            study.tell(trial, state=optuna.trial.TrialState.FAIL)
            continue
        trials.append(trial)
        candidates.append(candidate)
    if not candidates:
        raise HarnessError("hunt stopped: no proposal made a valid scenario")
    return trials, candidates


def _confirmed(failing: Outcome, run_batch: RunBatch, result: Hunt) -> bool:
    """Does `failing` fail the same way again? One that does not is kept as flaky."""
    again = run_batch([failing.candidate])[0]
    result.confirm_runs += 1
    assert failing.assessment is not None
    if again.assessment is not None and failing.assessment.same_way(again.assessment):
        return True
    result.flaky.append(failing)
    return False


def _shrink(result: Hunt, run_batch: RunBatch, plan: HuntPlan) -> None:
    """Keep the first simpler candidate that fails the same way (``shrink``), within budget."""
    assert result.found is not None and result.found.assessment is not None
    way = result.found.assessment
    current = result.found
    rejected: set[str] = set()  # a change that did not keep the failure is not tried again
    while result.shrink_runs < plan.shrink_budget:
        steps = [s for s in simplifications(current.candidate) if s[0] not in rejected]
        taken = None
        for start in range(0, len(steps), plan.batch):
            room = plan.shrink_budget - result.shrink_runs
            chunk = steps[start : start + min(plan.batch, room)]
            if not chunk:
                break
            outcomes = run_batch([candidate for _, candidate in chunk])
            result.shrink_runs += len(chunk)
            for (what, _), outcome in zip(chunk, outcomes, strict=True):
                if outcome.assessment is not None and way.same_way(outcome.assessment):
                    taken = (what, outcome)
                    break
                rejected.add(what)
            if taken is not None:
                break
        if taken is None:
            break
        result.shrink_steps.append(taken[0])
        current = taken[1]
    result.shrunk = current
