"""What the embedded cluster's workers are forked with: a fork keeps only the thread that
forks, so the modules its fork server imports first (harness.cluster.client's `preload`,
named by each command) must start no thread a worker could inherit the locks of: no
rclpy (its import starts LTTng-UST's two listener threads). numpy's OpenBLAS thread is in
Dask's own preload and forks safely."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

COMMANDS = Path(__file__).resolve().parents[1] / "harness" / "commands"


def preloaded_modules() -> set[str]:
    """Every module a command names as `preload=` (WARM_WORKER's value resolved)."""
    from harness.commands.cluster_options import WARM_WORKER

    found = set()
    for path in COMMANDS.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.keyword) and node.arg == "preload":
                for element in getattr(node.value, "elts", []):
                    if isinstance(element, ast.Constant):
                        found.add(element.value)
                    elif isinstance(element, ast.Name) and element.id == "WARM_WORKER":
                        found.add(WARM_WORKER)
    return found


def test_the_commands_name_their_preloads() -> None:
    assert {"harness.runner.warm_worker", "harness.grading.grade"} <= preloaded_modules()


@pytest.mark.parametrize("module", sorted(preloaded_modules()))
def test_a_preloaded_module_starts_no_thread_beyond_numpys(module: str) -> None:
    probe = (
        "import os, sys\n"
        "import numpy\n"
        "before = len(os.listdir('/proc/self/task'))\n"
        f"import {module}\n"
        "print(len(os.listdir('/proc/self/task')) - before, 'rclpy' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, timeout=60, check=True
    )
    assert done.stdout.split() == ["0", "False"], done.stdout + done.stderr
