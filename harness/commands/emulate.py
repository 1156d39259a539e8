"""`fossbot-hil emulate`: serve a scenario's scans as a LIDAR device.

Exit 1 when the scenario ran out and nothing ever read, so a script notices;
else 0 (the scenario's end, Ctrl-C or SIGTERM).
"""

from __future__ import annotations

import argparse

from rich.console import Console

from harness.commands.arguments import FAULTS_METAVAR, check_port, fault_list, lidar_mount, seed
from harness.links.kinds import device_names

NAME = "emulate"
HELP = "serve a scenario's scans as a LIDAR device on a serial port"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("device", choices=device_names(), help="the LIDAR to emulate")
    parser.add_argument(
        "--scenario", required=True, metavar="NAME", help="shipped scenario name or scenario file"
    )
    parser.add_argument(
        "--port",
        metavar="DEV",
        help="serial port to serve on (default: a new pty; its path is printed first, then "
        "a 'modem lines: export ...' line: run a pyserial client in a shell with it, and "
        "its DTR/RTS calls succeed and reach the emulator, the motor following DTR)",
    )
    parser.add_argument("--seed", type=seed, help="override the scenario's seed")
    parser.add_argument(
        "--faults",
        metavar=FAULTS_METAVAR,
        help="fault profiles or inline faults such as drop(rate=0.1), replacing the scenario's "
        "own; of the link faults, only rate_drift and line faults (see docs/faults.md)",
    )
    parser.add_argument(
        "--lidar-mount",
        type=lidar_mount,
        metavar="MOUNT",
        help="how the device sits on the robot: model (default: what the scenario's robot "
        "model says; the FOSSBot v2's A1 has its zero to the right), forward (zero straight "
        "ahead), or DEG[,mirrored] (see docs/hil.md)",
    )
    parser.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="log every request, answer and protocol error (default: a status line every 5 s)",
    )


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.devices.profiles import profile
    from harness.runner.emulate import emulate
    from harness.runner.settings import RunSettings
    from harness.scenario.files import resolve_scenario

    if args.port is not None:
        check_port("--port", args.port)
    scenario = resolve_scenario(args.scenario)
    settings = RunSettings(seed=args.seed, faults=fault_list(args.faults))
    if args.lidar_mount is not None:
        mount = args.lidar_mount
    else:
        from harness.scenario.mount import scenario_mount

        mount = scenario_mount(scenario)
    summary = emulate(
        profile(args.device),
        scenario,
        port=args.port,
        settings=settings,
        announce=_print_safe,
        verbose=args.verbose,
        mount=mount,
    )
    for line in summary.lines():
        _print_safe(line)
    return 1 if summary.stopped_by is None and summary.client_read is False else 0


def _print_safe(line: str) -> None:
    """A line at once (scripts read the port's path first); the host's bytes shown safely."""
    from harness.safe_text import for_terminal

    print(for_terminal(line), flush=True)
