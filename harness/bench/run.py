"""Run the bench stages in one process, one after the other, and collect the figures.

Stages run in a fixed order, cheapest first; a stage that fails (no rclpy,
a node that did not start) is reported with its reason and the others
still run. Everything is measured on this machine in this run, so the
ratios between stages hold even when the absolute numbers move with load.
"""

from __future__ import annotations

import importlib
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


#: Each stage's module (imported when the stage runs: ROS stages need rclpy only when
#: selected) and how it is measured for a plan.
_MEASURES: dict[str, tuple[str, Callable[[Any, BenchPlan], StageResult]]] = {
    "raycast": ("raycast", lambda m, p: m.measure_raycast(p.workload)),
    "synthesis": ("synthesis", lambda m, p: m.measure_synthesis(p.workload)),
    INPROCESS: ("inprocess", lambda m, p: m.measure_inprocess(p.workload)),
    ROS2: ("ros2_lockstep", lambda m, p: m.measure_ros2(p.workload)),
    "serial": ("serial_lockstep", lambda m, p: m.measure_serial(p.serial_workload)),
    "pacing": ("serial_pacing", lambda m, p: m.measure_pacing(p.workload.scenarios[0], p.pacing_s)),
    "suite": (
        "lab_suite",
        lambda m, p: m.measure_suite(
            lab_workload(1, p.suite_scenarios or LAB_TRIO),
            cli=not p.quick,  # the lab trio's CLI in a fresh process too
            suite_runs=p.suite_runs,
            student_split=not p.quick,  # quick: no more suites of student node starts
            suite=p.suite_scenarios,
        ),
    ),
    "grade": (
        "grade_class",
        lambda m, p: m.measure_grade(p.grade_students, p.suite_scenarios, runs=not p.quick),
    ),
    "hil": ("hil_board", lambda m, p: m.measure_hil(m.QUICK_SUITE if p.quick else ())),
}


def _measure(name: str, plan: BenchPlan) -> StageResult:
    """Run one stage."""
    if name not in _MEASURES:
        raise ValueError(name)
    module, measure = _MEASURES[name]
    return measure(importlib.import_module(f"harness.bench.{module}"), plan)


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
