"""`fossbot-hil ports`: the serial adapters a `--port` could name."""

from __future__ import annotations

import argparse

from rich.console import Console

NAME = "ports"
HELP = "list serial adapters (for --port)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.serial_line.ports import list_serial_ports

    ports = list_serial_ports()
    for port in ports:
        console.print(port.line(), markup=False)
    if not ports:
        console.print("no serial adapters found (plug in the USB-UART, then try again)")
    return 0
