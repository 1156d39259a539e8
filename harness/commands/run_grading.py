"""`run --grading FILE` and `run --gradescope FILE`: one submission, scored as `grade` scores it.

`--grading` takes the scenarios, weights, hidden scenarios, points and judging
options from the instructor's grading file (harness.grading.grading_file);
options typed on the command line win over the file's. Since `run` is what a
student (or Gradescope, for a student) runs, a hidden scenario is shown on the
terminal and in the JUnit XML by its label and whether it passed, and the
options that would show more of it (a report folder, the viewer, a baseline,
the last run's order) are refused. `--gradescope` writes Gradescope's
results.json after the suite (harness.grading.gradescope); without a grading
file every scenario weighs 1.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from rich.console import Console

from harness.commands.arguments import check_output_file, not_empty
from harness.errors import ConfigError
from harness.judge.verdicts import RunVerdict

if TYPE_CHECKING:  # imported when a run starts (the parser is built for any command)
    from harness.grading.grading_file import GradingFile
    from harness.grading.scoring import ScorePlan
    from harness.judge.records import RunResult
    from harness.runner.settings import RunSettings
    from harness.scenario.schema import Scenario

__all__ = ["RunGrading", "add_grading_options", "apply_grading"]

#: What would show a hidden scenario's name, file, world or ticks, and why.
SHOWS_HIDDEN = {
    "out": "a report folder holds each scenario's plot, world and recording",
    "gui": "the viewer shows each scenario's world",
    "baseline": "a baseline is compared scenario by scenario, by name",
    "failed_first": "it names the scenarios that failed last time",
    "watch": "a loop names the scenarios it reruns",
}
NODE_IN_WORKSPACE = ("package", "executable")  # a grading file's, used only with --workspace


def add_grading_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("grading (see docs/grading.md)")
    group.add_argument(
        "--grading",
        type=not_empty,
        metavar="FILE",
        help="grading file (YAML): the scenarios, their weights, hidden scenarios, points and "
        "judging options (options typed on the command line win); a hidden scenario is shown "
        "only by its label and whether it passed",
    )
    group.add_argument(
        "--gradescope",
        type=not_empty,
        metavar="FILE",
        help="after the suite, write Gradescope's autograder results (results.json) to FILE: "
        "the score and a test per scenario (see examples/gradescope/)",
    )


def apply_grading(args: argparse.Namespace) -> RunGrading:
    """--grading's file read, its scenarios set on `args` and its options under the typed
    ones (``args.under``, which `request_of` reads), and --gradescope's FILE checked: all
    before anything runs."""
    gradescope = getattr(args, "gradescope", None)
    check_output_file("--gradescope", gradescope)
    if gradescope and args.watch:
        raise ConfigError("--gradescope cannot go with --watch: a loop has no last results")
    source = getattr(args, "grading", None)
    if not source:
        return RunGrading(None, gradescope)
    from harness.grading.grading_file import load_grading_file

    grading = load_grading_file(source)
    if args.scenarios:
        raise ConfigError(
            f"SCENARIO and --grading {source}: the grading file lists the scenarios "
            "(give one of them)"
        )
    # the lab's node in a workspace; a --node or the reference node runs otherwise
    skip = () if args.workspace else NODE_IN_WORKSPACE
    args.under = {k: v for k, v in grading.request_values().items() if k not in skip}
    args.scenarios = [p.scenario for p in grading.planned]
    if any(p.hidden for p in grading.planned):
        for name, why in SHOWS_HIDDEN.items():
            if getattr(args, name, None):
                option = f"--{name.replace('_', '-')}"
                raise ConfigError(
                    f"{option} cannot go with --grading {source}: it has hidden scenarios, "
                    f"and {why}"
                )
    return RunGrading(grading, gradescope)


@dataclass
class RunGrading:
    """The run's grading file and Gradescope file, and once the scenarios are known
    (`bind`), how they are scored and shown."""

    grading: GradingFile | None
    gradescope: str | None
    plan: ScorePlan | None = None
    scenarios: list[Scenario] = field(default_factory=list)

    @property
    def active(self) -> bool:
        return self.grading is not None or self.gradescope is not None

    def bind(self, scenarios: Sequence[Scenario]) -> None:
        """The plan for the scenarios `prepared` resolved (in the grading file's order)."""
        if not self.active:
            return
        from harness.grading.scoring import ScorePlan

        names = [s.name for s in scenarios]
        twice = next((n for i, n in enumerate(names) if n in names[:i]), None)
        if twice is not None:
            where = f"--grading {self.grading.source}" if self.grading else "SCENARIO"
            raise ConfigError(f"{where}: scenario {twice} is given twice (score it once)")
        self.scenarios = list(scenarios)
        if self.grading is None:
            self.plan = ScorePlan.equal(names)
            return
        self.plan = self.grading.score_plan(names)

    @property
    def hidden_names(self) -> dict[str, str]:
        """What a student must not read -> what they read instead: each hidden scenario's
        name, file path and file name -> its label."""
        if self.plan is None:
            return {}
        names: dict[str, str] = {}
        for entry, scenario in zip(self.plan.scenarios, self.scenarios, strict=True):
            if not entry.hidden:
                continue
            names[entry.name] = entry.shown_name
            if scenario.source:
                source = Path(scenario.source)
                names[str(source)] = names[source.name] = entry.shown_name
                names[str(source.resolve())] = entry.shown_name
        return names

    def shown_names(self, scenarios: Sequence[Scenario]) -> list[str]:
        """The scenarios' names as the terminal shows them (a hidden one's label)."""
        if self.plan is None:
            return [s.name for s in scenarios]
        return [self.plan.entry(s.name).shown_name for s in scenarios]

    def shown(self, results: Sequence[RunResult]) -> list[RunResult]:
        """The results as a student sees them: a hidden scenario by its label and whether
        it passed (its first failure only if allowed); no other text names it."""
        if self.plan is None or not self.plan.hidden:
            return list(results)
        from harness.grading.hidden import HiddenScenario, hidden_run
        from harness.grading.student_text import hide_names

        names = self.hidden_names
        shown: list[RunResult] = []
        for result in results:
            entry = self.plan.entry(result.scenario)
            if entry.hidden:
                seen = HiddenScenario(entry.shown_name, entry.show_failure)
                shown.append(hidden_run(result, seen))
            elif result.error:
                shown.append(replace(result, error=hide_names(result.error, names)))
            else:
                shown.append(result)
        return shown

    def finish(
        self,
        console: Console,
        results: Sequence[RunResult],
        args: argparse.Namespace,
        wall_s: float,
    ) -> None:
        """The score on the terminal, and --gradescope's results.json."""
        if self.plan is None:
            return
        from harness.commands.run_steps import settings_from, write_report_file
        from harness.grading.scoring import points_text
        from harness.report.console_text import print_safe

        plan = self.plan
        verdicts, failures = _verdicts(results, plan.names)
        ticks: dict[str, tuple[int, int]] = {}
        if self.gradescope is not None or plan.partial_credit:
            ticks = _ticks(results, verdicts, self.scenarios, settings_from(args))
        score = plan.score(verdicts, ticks)
        print_safe(console, f"score: {points_text(score)} of {points_text(plan.max_score)}")
        if self.gradescope is None:
            return
        import json

        from harness.atomic_write import write_atomically
        from harness.grading.gradescope import gradescope_results
        from harness.report.terminal import run_notes

        passed = sum(1 for v in verdicts.values() if v == RunVerdict.PASS)
        data = gradescope_results(
            plan,
            verdicts,
            ticks,
            failures,
            notes=run_notes(results),
            execution_time=wall_s,
            output=f"{passed} of {len(plan.scenarios)} scenarios passed",
            hidden_names=self.hidden_names,
        )
        text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
        where = self.gradescope
        write_report_file(f"--gradescope {where}", write_atomically, where, text.encode("utf-8"))
        print_safe(console, f"gradescope: {where}")


def _verdicts(
    results: Sequence[RunResult], names: Sequence[str]
) -> tuple[dict[str, str], dict[str, str]]:
    """Each scenario's verdict (NOT RUN when it has no result) and first failure in words."""
    from harness.grading.class_table import NOT_RUN, PASS
    from harness.judge.verdicts import verdict_of

    by_name = {r.scenario: r for r in results}
    verdicts: dict[str, str] = {}
    failures: dict[str, str] = {}
    for name in names:
        result = by_name.get(name)
        verdicts[name] = NOT_RUN if result is None else verdict_of(result)
        if result is not None and verdicts[name] != PASS:
            failures[name] = result.first_failure or result.error or ""
    return verdicts, failures


def _ticks(
    results: Sequence[RunResult],
    verdicts: dict[str, str],
    scenarios: Sequence[Scenario],
    settings: RunSettings,
) -> dict[str, tuple[int, int]]:
    """(ticks held, ticks the scenario runs when nothing breaks) of each scenario: one that
    broke early, or never ran, counts its missing ticks as not held."""
    from harness.grading.scoring import held_of
    from harness.runner.planned_ticks import planned_ticks

    by_name = {r.scenario: r for r in results}
    unfinished = [s for s in scenarios if verdicts.get(s.name) != RunVerdict.PASS]
    planned = planned_ticks(unfinished, settings) if unfinished else {}
    ticks: dict[str, tuple[int, int]] = {}
    for scenario in scenarios:
        result = by_name.get(scenario.name)
        judged = len(result.records) if result is not None else 0
        failed = len(result.failed_ticks) if result is not None else 0
        counted = held_of(judged, failed, planned.get(scenario.name, 0))
        if counted is not None:
            ticks[scenario.name] = counted
    return ticks
