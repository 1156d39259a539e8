"""`fossbot-hil emulate`: serve a scenario's scans as a LIDAR device."""

from __future__ import annotations

import argparse

from rich.console import Console

from harness.commands.arguments import check_port, fault_list, seed

NAME = "emulate"
HELP = "serve a scenario's scans as a LIDAR device on a serial port"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("device", choices=["rplidar", "ldlidar"])
    parser.add_argument(
        "--scenario", required=True, metavar="NAME", help="shipped scenario name or scenario file"
    )
    parser.add_argument(
        "--port",
        metavar="DEV",
        help="serial port to serve on (default: a new pty; its path is printed)",
    )
    parser.add_argument("--seed", type=seed, help="override the scenario's seed")
    parser.add_argument("--faults", metavar="NAME[,NAME]", help="fault profiles to apply")


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.devices.profiles import profile
    from harness.runner.emulate import emulate
    from harness.runner.settings import RunSettings
    from harness.scenario.files import resolve_scenario

    if args.port is not None:
        check_port("--port", args.port)
    scenario = resolve_scenario(args.scenario)
    settings = RunSettings(seed=args.seed, faults=fault_list(args.faults))
    summary = emulate(
        profile(args.device),
        scenario,
        port=args.port,
        settings=settings,
        announce=lambda line: print(line, flush=True),
    )
    rate = summary.mean_rate_error_pct
    console.print(
        f"served {summary.revolutions_streamed} of {summary.revolutions} revolutions "
        f"({summary.bytes_written} bytes"
        + (f", line rate error {rate:+.2f} %" if rate is not None else "")
        + ")",
        markup=False,
    )
    return 0
