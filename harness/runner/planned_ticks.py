"""How many ticks a scenario runs when nothing breaks: what a partial score counts against.

The robot's motion is scripted (obstacle conditions read the simulated truth,
not the node), so the count is the simulation's alone: a scenario whose run
broke early still has its missing ticks counted as not held.
"""

from __future__ import annotations

from collections.abc import Sequence

from harness.links.base import LinkOptions
from harness.runner.plan import plan_one
from harness.runner.settings import RunSettings
from harness.scenario.schema import Scenario

__all__ = ["planned_ticks"]


def planned_ticks(scenarios: Sequence[Scenario], settings: RunSettings) -> dict[str, int]:
    """Each scenario's tick count, simulated without a link (pybullet, no ROS), as a run
    simulates it: where frames are remembered (harness.runner.frame_memo), they are kept
    for the runs, or the judges, that follow."""
    from harness.runner.frame_memo import frames_of, keeping
    from harness.runner.scenario_run import simulated_frames

    counts: dict[str, int] = {}
    for scenario in scenarios:
        plan = plan_one(scenario, "", LinkOptions(), settings)  # no link: the ticks are its own
        kept = frames_of(plan)
        if kept is not None:
            counts[scenario.name] = len(kept)
            continue
        with simulated_frames(plan) as frames:  # kept by `keeping` where remembered
            counts[scenario.name] = sum(1 for _ in keeping(plan, frames))
    return counts
