"""Shared by the plugin's tests: pytest runs pytest (pytester).

pytester's in-process runs forget every module first imported inside them.
numpy refuses a second import in one process, and re-importing hypothesis
(its pytest plugin loads it in every run) costs seconds each time; so they,
and what the plugin imports lazily, are imported here once, before any run.
"""

from __future__ import annotations

import contextlib

import harness.commands.arguments  # noqa: F401 - numpy, through the links
import harness.faults.sensor  # noqa: F401
import harness.runner.suite  # noqa: F401
import harness.scenario.files  # noqa: F401

with contextlib.suppress(ImportError):
    import hypothesis  # noqa: F401
