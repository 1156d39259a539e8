"""`fossbot-hil run` as a user types it, timed from spawn to exit, several kinds alternated.

The kinds of run take turns (a, b, c, a, b, c, ...) rather than running in
blocks, so a change in the machine's load falls on all of them alike and
the ratios between their medians hold within one bench.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence

from harness.errors import HarnessError
from harness.run_request.table import option

CLI_TIMEOUT_S = 120.0  # the shipped suite takes 2-12 s here; a hung run ends the stage
# The commands' own flags the bench gives (not run options): `run`'s and `grade`'s.
COMMAND_FLAGS = {"out": "--out", "no_audit": "--no-audit", "scenario": "--scenario"}


def cli_args(**given: str) -> list[str]:
    """Options by key as `fossbot-hil run` takes them: a run option's flag as the run
    request's table spells it, `run`'s own as COMMAND_FLAGS does."""
    args: list[str] = []
    for key, value in given.items():
        flag = COMMAND_FLAGS.get(key) or option(key).cli
        assert flag is not None, f"{key}: not an option of fossbot-hil run"
        args += [flag, value]
    return args


def _fossbot_hil() -> list[str]:
    """The command beside this Python (the venv's entry point), else the module."""
    exe = shutil.which("fossbot-hil", path=os.path.dirname(sys.executable))
    return [exe] if exe else [sys.executable, "-m", "harness.cli"]


def spawn_s(args: Sequence[str], what: str, timeout_s: float) -> float:
    """`fossbot-hil ARGS` from spawn to exit; HarnessError naming `what` unless it exits 0."""
    started = time.perf_counter()
    try:
        done = subprocess.run(
            [*_fossbot_hil(), *args], capture_output=True, timeout=timeout_s, check=False
        )
    except subprocess.TimeoutExpired:
        raise HarnessError(f"{what} took longer than {timeout_s:g} s") from None
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).decode(errors="replace").strip()[-300:]
        raise HarnessError(f"{what} exited {done.returncode}: {tail}")
    return seconds


def cli_wall_s(args: Sequence[str]) -> float:
    """`fossbot-hil run ARGS` from spawn to exit; HarnessError unless it exits 0 (all passed)."""
    return spawn_s(["run", *args], f"fossbot-hil run {shlex.join(args)}", CLI_TIMEOUT_S)


def alternate(kinds: Mapping[str, Sequence[str]], rounds: int) -> dict[str, list[float]]:
    """Each kind's `fossbot-hil run` arguments, run once per round in the mapping's order."""
    walls: dict[str, list[float]] = {name: [] for name in kinds}
    for _ in range(rounds):
        for name, args in kinds.items():
            walls[name].append(cli_wall_s(args))
    return walls
