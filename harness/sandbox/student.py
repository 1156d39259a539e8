"""One student's sandboxes, as the grader starts them: the build, the judging run, and
the node's nested sandbox (its command goes to the judging process's environment)."""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path

from harness.nodes.sandbox_prefix import NODE_SANDBOX_ENV
from harness.sandbox.bwrap import bwrap_argv
from harness.sandbox.limits import SandboxLimits
from harness.sandbox.views import build_view, node_view, run_view

__all__ = ["sandboxed_build", "sandboxed_run"]


def sandboxed_build(
    command: Sequence[str], student_folder: Path, colcon_folder: Path, limits: SandboxLimits
) -> list[str]:
    """colcon's command line, run in the build's sandbox under `limits`."""
    return bwrap_argv(build_view(student_folder, colcon_folder), [*limits.prefix(), *command])


def sandboxed_run(
    command: Sequence[str],
    *,
    node_files: Iterable[Path],
    scenario_files: Iterable[Path],
    outputs: Iterable[Path],
    limits: SandboxLimits,
) -> list[str]:
    """The judging process's command line in its sandbox; its nodes start in theirs."""
    node_files = list(node_files)
    nested = bwrap_argv(node_view(node_files), limits.prefix())
    view = run_view(node_files, scenario_files, outputs, {NODE_SANDBOX_ENV: json.dumps(nested)})
    return bwrap_argv(view, command)
