"""`fossbot-hil list`: the shipped scenarios."""

from __future__ import annotations

import argparse
import io

from rich.console import Console

NAME = "list"
HELP = "list the shipped scenarios"


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
