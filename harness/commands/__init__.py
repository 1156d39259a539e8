"""The `fossbot-hil` subcommands, one module each.

A command module has ``NAME``, ``HELP`` (its line in ``fossbot-hil
--help``, and its own ``--help``'s description unless it has a longer
``DESCRIPTION``), ``add_arguments(parser)`` and ``run(args, console) ->
int``. Add a command by writing a module and naming it in
``COMMAND_MODULES``; nothing else changes.
"""

from __future__ import annotations

import importlib
from types import ModuleType

COMMAND_MODULES = (
    "list_scenarios",
    "run",
    "sim",
    "ports",
    "emulate",
    "replay",
    "grade",
    "sweep",
    "audit",
    "hunt",
    "bench",
)


def command_modules() -> list[ModuleType]:
    """The command modules, in the order `--help` lists them."""
    return [importlib.import_module(f"harness.commands.{name}") for name in COMMAND_MODULES]
