"""What to simulate: scenario files, their schema, their checks, and lookup.

A scenario is a YAML file: the world, the robot's start pose, its LIDAR, a
motion script, the fault profile and the warning threshold. Every mistake
in a file becomes one ``ConfigError`` line naming the file and the field.

- ``files``: a name or a path to a checked ``Scenario`` (the entry point);
- ``schema``: what each field may hold; ``limits``: how much a file may ask;
- ``checks``: rules across fields and files (run length, reachable
  conditions, model files, a start clear of obstacles), with ``ahead``,
  ``footprint``, ``geometry`` and ``model_files`` as their pure helpers;
- ``mount``: where the LIDAR device's zero points, read from the robot
  model (``scenario_mount``);
- ``yaml_loader``: YAML 1.2 core only, bounded;
- ``variations``: a scenario with its wall moved, its start moved or its
  speed scaled, checked as a file is (a campaign's generated factors).

Pure: pydantic and numpy, no pybullet. Add a check in ``checks``, a field
in ``schema`` (and docs/scenarios.md).
"""

from harness import lazy_exports

_EXPORTS = {
    "Scenario": "schema",
    "parse_scenario": "files",
    "load_scenario_file": "files",
    "resolve_scenario": "files",
    "shipped_scenarios": "files",
    "shipped_dir": "files",
    "scenario_mount": "mount",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
