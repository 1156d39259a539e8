"""Drives everything: a scenario simulated, spoiled, delivered and judged; a suite; a replay.

- ``scenario_run``: one scenario through a link (``run``, ``run_scenario``);
- ``frames``: the lockstep loop every run shares (``judge_frames``);
- ``settings``: what a run may override, checked before any run starts;
- ``suite``: scenarios in order, each with a fresh link, ``link_pipeline``
  starting the next ones ahead and stopping finished ones behind;
- ``replay``: a recorded scan stream judged the same way;
- ``emulate``: a scenario's scans served as a LIDAR device on a port.

The commands, the pytest plugin, grading and the bench all run through here.
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
