"""`fossbot-hil list`: the shipped scenarios."""

from __future__ import annotations

import argparse

from rich.console import Console

NAME = "list"
HELP = "list the shipped scenarios"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.report.terminal import scenario_table
    from harness.scenario.files import shipped_scenarios

    console.print(scenario_table(shipped_scenarios()))
    return 0
