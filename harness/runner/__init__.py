"""Drives everything: a scenario simulated, spoiled, delivered and judged; a suite; a replay.

The commands, the pytest plugin, grading and the bench all run through here
(the modules: docs/architecture.md).
"""

from harness import lazy_exports

_EXPORTS = {
    "RunSettings": "settings",
    "run": "scenario_run",
    "run_scenario": "scenario_run",
    "run_suite": "suite",
    "judge_frames": "frames",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
