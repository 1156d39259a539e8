"""`fossbot-hil ports`: the serial adapters a `--port` could name, what each is, and
whether this user may open it."""

from __future__ import annotations

import argparse

from rich.console import Console

NAME = "ports"
HELP = "list serial adapters (for --port): what each likely is, and whether you may open it"
DESCRIPTION = (
    "List this machine's serial ports, the ones a --port (of run, replay, emulate) could "
    "name: each port's path, its USB vendor:product id, the chip it likely is (the RPLIDAR "
    "A1's own adapter is a CP2102), and whether you may open it, with the fix when not "
    "(docs/hil.md)."
)

NO_USB_ID = "-"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.safe_text import for_terminal
    from harness.serial_line.adapters import access_problem, likely_adapter
    from harness.serial_line.ports import list_serial_ports

    ports = list_serial_ports()
    if not ports:
        console.print("no serial adapters found (plug in the USB-UART, then try again)")
        return 0
    rows = [("PORT", "USB ID", "LIKELY", "MAY OPEN")]
    for port in ports:
        problem = access_problem(port.device)
        may_open = "yes" if problem is None else f"no: {problem}"
        likely = likely_adapter(port.device, port.vid_pid)
        rows.append((port.device, port.vid_pid or NO_USB_ID, likely, may_open))
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    for row in rows:
        cells = [cell.ljust(width) for cell, width in zip(row, widths, strict=False)]
        console.print(for_terminal("  ".join([*cells, row[3]])), markup=False)
    for port in ports:
        if port.description or port.serial_number:
            sn = f" SN={port.serial_number}" if port.serial_number else ""
            console.print(for_terminal(f"{port.device}: {port.description}{sn}"), markup=False)
    if any(port.vid_pid is None for port in ports):
        console.print(
            f"USB ID {NO_USB_ID}: not a USB device (a built-in or virtual UART), so no "
            "vendor:product id to tell the chip by",
            markup=False,
        )
    return 0
