"""What to simulate: scenario files, their schema, their checks, and lookup.

A scenario is a YAML file (world, start pose, LIDAR, motion, faults,
threshold); every mistake in one becomes one ``ConfigError`` line naming
the file and the field. ``files`` is the entry point; docs/architecture.md
lists the rest. Pure: pydantic and numpy, no pybullet. Add a check in
``checks``, a field in ``schema`` (and docs/scenarios.md).
"""

from harness import lazy_exports

_EXPORTS = {
    "Scenario": "schema", "parse_scenario": "files", "load_scenario_file": "files",
    "resolve_scenario": "files", "shipped_scenarios": "files", "shipped_dir": "files",
    "scenario_mount": "mount",
}  # fmt: skip
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
