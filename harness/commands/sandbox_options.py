"""`grade`'s sandbox options, and the check that each student can be sandboxed here."""

from __future__ import annotations

import argparse
from typing import Any

from rich.console import Console

from harness.commands.arguments import whole_number
from harness.errors import ConfigError
from harness.report.console_text import print_safe as say
from harness.sandbox.limits import SandboxLimits

__all__ = ["add_sandbox_options", "sandbox_limits", "check_workers"]

DEFAULTS = SandboxLimits()
NO_SANDBOX_WARNING = (
    "warning: --no-sandbox: each student's build and node run with your rights (they can "
    "read the other submissions and the hidden scenarios, write your files, reach the network)"
)


def add_sandbox_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "sandbox (each student's build and node run in bubblewrap; see docs/grading.md)"
    )
    group.add_argument(
        "--no-sandbox",
        action="store_true",
        help="run students' code unsandboxed, with your rights (only for code you trust)",
    )
    group.add_argument(
        "--sandbox-memory",
        type=whole_number("--sandbox-memory", 256, 1 << 20),
        default=DEFAULTS.memory_mb,
        metavar="MB",
        help=f"memory of any one process of a student's build or node "
        f"(default {DEFAULTS.memory_mb})",
    )
    group.add_argument(
        "--sandbox-processes",
        type=whole_number("--sandbox-processes", 16, 1 << 16),
        default=DEFAULTS.processes,
        metavar="N",
        help=f"processes a student's build or node may run at once (default "
        f"{DEFAULTS.processes}; Linux does not apply it to a grader run as root)",
    )


def sandbox_limits(args: argparse.Namespace, console: Console) -> SandboxLimits | None:
    """The sandbox's limits, or None with --no-sandbox (said in a warning line). A machine
    that cannot sandbox is a usage error (exit 2) before any student runs."""
    from harness.sandbox.probe import sandbox_problem

    if args.no_sandbox:
        say(console, NO_SANDBOX_WARNING)
        return None
    problem = sandbox_problem()
    if problem is not None:
        raise ConfigError(problem)
    return SandboxLimits(args.sandbox_memory, args.sandbox_processes)


def check_workers(client: Any, console: Console) -> None:
    """Each cluster worker tries a sandbox: none can is a usage error; some cannot is a
    warning line (their students' rows then say why they were not graded)."""
    from harness.sandbox.probe import sandbox_problem

    problems = {w: p for w, p in client.run(sandbox_problem).items() if p is not None}
    if not problems:
        return
    if len(problems) == len(client.scheduler_info().get("workers", {})):
        raise ConfigError(next(iter(problems.values())))
    for worker, problem in sorted(problems.items()):
        say(
            console,
            f"warning: worker {worker} cannot sandbox, its students are not graded: {problem}",
        )
