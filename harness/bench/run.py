"""Run the bench stages in one process, one after the other, and collect the figures.

Stages run in a fixed order, cheapest first; a stage that fails (no rclpy,
a node that did not start) is reported with its reason and the others
still run. Everything is measured on this machine in this run, so the
ratios between stages hold even when the absolute numbers move with load.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from harness.bench import STAGES, machine
from harness.bench.figures import OVERHEAD_FORMULA, check_targets, figures
from harness.bench.stage import StageResult
from harness.bench.workload import LAB_TRIO, Workload, lab_workload
from harness.errors import HarnessError, OptionError
from harness.links.kinds import INPROCESS, ROS2


@dataclass(frozen=True)
class BenchPlan:
    """How much each stage does: the default run, or `quick` (for tests)."""

    quick: bool = False
    stages: tuple[str, ...] = STAGES

    @property
    def workload(self) -> Workload:
        """Scans for the raycast, synthesis, inprocess and ros2 stages."""
        return lab_workload(1, ("approach_wall",)) if self.quick else lab_workload(2)

    @property
    def serial_workload(self) -> Workload:
        """The serial link is the slowest: the same scenarios, once."""
        return lab_workload(1, ("approach_wall",)) if self.quick else lab_workload(1)

    @property
    def pacing_s(self) -> float:
        """Seconds of real-time streaming: 30 s is 300 revolutions at 10 Hz, 299
        intervals, so the p99 is the third largest. One late revolution start
        moves two intervals (one long, one short): with 149 intervals a
        single one in the whole stream set the p99."""
        return 1.0 if self.quick else 30.0

    @property
    def suite_scenarios(self) -> tuple[str, ...]:
        """The suite stage's scenarios (quick: approach_wall alone; else all of them)."""
        return ("approach_wall",) if self.quick else ()

    @property
    def suite_runs(self) -> int:
        """`fossbot-hil run`s of each of the suite's three kinds (the median kept)."""
        return 1 if self.quick else 3

    @property
    def grade_students(self) -> int:
        """The grade stage's class: four students (two per worker on 2 cores; quick: two)."""
        return 2 if self.quick else 4


def parse_stages(text: str | None) -> tuple[str, ...]:
    """``--only a,b``: known stage names, in the bench's own order."""
    if text is None:
        return STAGES
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in STAGES]
    if unknown or not names:
        raise OptionError.saying(
            "only",
            f"{text!r}: unknown stage {', '.join(unknown) or '(none given)'} "
            f"(known: {', '.join(STAGES)})",
        )
    return tuple(s for s in STAGES if s in names)


def _measure(name: str, plan: BenchPlan) -> StageResult:
    """Run one stage (imports here: ROS stages need rclpy only when selected)."""
    if name == "raycast":
        from harness.bench.raycast import measure_raycast

        return measure_raycast(plan.workload)
    if name == "synthesis":
        from harness.bench.synthesis import measure_synthesis

        return measure_synthesis(plan.workload)
    if name == INPROCESS:
        from harness.bench.inprocess import measure_inprocess

        return measure_inprocess(plan.workload)
    if name == ROS2:
        from harness.bench.ros2_lockstep import measure_ros2

        return measure_ros2(plan.workload)
    if name == "serial":
        from harness.bench.serial_lockstep import measure_serial

        return measure_serial(plan.serial_workload)
    if name == "pacing":
        from harness.bench.serial_pacing import measure_pacing

        return measure_pacing(plan.workload.scenarios[0], plan.pacing_s)
    if name == "suite":
        from harness.bench.lab_suite import measure_suite

        return measure_suite(
            lab_workload(1, plan.suite_scenarios or LAB_TRIO),
            cli=not plan.quick,  # the lab trio's CLI in a fresh process too
            suite_runs=plan.suite_runs,
            student_split=not plan.quick,  # quick: no more suites of student node starts
            suite=plan.suite_scenarios,
        )
    if name == "grade":
        from harness.bench.grade_class import measure_grade

        return measure_grade(plan.grade_students, plan.suite_scenarios, runs=not plan.quick)
    if name == "hil":
        from harness.bench.hil_board import QUICK_SUITE, measure_hil

        return measure_hil(QUICK_SUITE if plan.quick else ())
    raise ValueError(name)


def run_bench(
    plan: BenchPlan, *, on_stage: Callable[[str, StageResult | None, float], None] | None = None
) -> dict[str, Any]:
    """Every selected stage; the JSON object `fossbot-hil bench --json` prints."""
    load_start = machine.load_average()
    started = time.perf_counter()
    stages: dict[str, StageResult] = {}
    errors: dict[str, str] = {}
    for name in plan.stages:
        stage_started = time.perf_counter()
        try:
            stages[name] = _measure(name, plan)
        except (HarnessError, RuntimeError, OSError) as err:
            errors[name] = (
                f"{type(err).__name__}: {err}" if not isinstance(err, HarnessError) else str(err)
            )
        if on_stage is not None:
            on_stage(name, stages.get(name), time.perf_counter() - stage_started)
    values = figures(stages, machine.peak_rss_mb())
    return {
        **values,
        "overhead_formula": OVERHEAD_FORMULA,
        "targets": check_targets(values),
        "stages": {name: _stage_summary(stage) for name, stage in stages.items()},
        "errors": errors,
        "quick": plan.quick,
        "bench_wall_s": time.perf_counter() - started,
        "machine": {
            **machine.describe(),
            "load_average_start": load_start,
            "load_average_end": machine.load_average(),
        },
    }


def _stage_summary(stage: StageResult) -> dict[str, Any]:
    return {
        "scans": stage.scans,
        "seconds": stage.seconds,
        "simulated_s": stage.simulated_s,
        **stage.extra,
    }
