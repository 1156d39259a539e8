"""`fossbot-hil list`: the shipped scenarios."""

from __future__ import annotations

import argparse
import io

from rich.console import Console

NAME = "list"
HELP = "list the shipped scenarios"
DESCRIPTION = (
    "List the scenarios shipped with fossbot-hil, one line each: its name, the LIDAR it "
    "simulates, its fault profiles and what it does. `run`, `emulate`, `sweep`, `grade` and "
    "`audit` take these names, or the path of a scenario file of your own (docs/scenarios.md)."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.report.terminal import scenario_table
    from harness.scenario.files import shipped_scenarios

    plain = Console(file=io.StringIO(), width=console.width, color_system=None)
    plain.print(scenario_table(shipped_scenarios()))
    text = plain.file.getvalue()  # type: ignore[attr-defined]
    for line in text.splitlines():  # a table pads every line to its width: not on output
        console.print(line.rstrip(), markup=False, highlight=False, soft_wrap=True)
    return 0
