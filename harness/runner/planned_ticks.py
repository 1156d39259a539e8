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
    """Each scenario's tick count, simulated without a link (pybullet, no ROS)."""
    from harness.sim.simulation import Simulation  # imports pybullet

    counts: dict[str, int] = {}
    for scenario in scenarios:
        plan = plan_one(scenario, "", LinkOptions(), settings)  # no link: the ticks are its own
        with Simulation(scenario) as sim:
            counts[scenario.name] = sum(1 for _ in sim.ticks(plan.periods()))
    return counts
