"""The `fossbot-hil` subcommands, one module each.

A command module has ``NAME``, ``HELP`` (and a longer ``DESCRIPTION``, if
any), ``add_arguments(parser)`` and ``run(args, console) -> int``; adding
one is naming it in ``COMMAND_MODULES``.
"""

from __future__ import annotations

import importlib
from types import ModuleType

COMMAND_MODULES = (
    "list_scenarios", "run", "sim", "ports", "emulate", "replay", "grade", "sweep", "audit", "hunt",
    "bench",
)  # fmt: skip


def command_modules() -> list[ModuleType]:
    """The command modules, in the order `--help` lists them."""
    return [importlib.import_module(f"harness.commands.{name}") for name in COMMAND_MODULES]
