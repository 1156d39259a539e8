"""`run --launch PACKAGE FILE`: the node started by ``ros2 launch``, where that is installed.

Checked before anything starts: the package has that launch file. Where
``ros2 launch`` is missing (ROS 2's launch is not on the package index),
what the file says is read anyway and printed, then one line says what to
do, exit 2. A run without --launch still checks the package's launch files
against the running node (docs/launch_files.md).
"""

from __future__ import annotations

import argparse

from rich.console import Console

from harness.commands.arguments import given
from harness.errors import ConfigError
from harness.links.kinds import either, link_kind, link_names

__all__ = ["add_launch_option", "check_launch"]


def add_launch_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--launch",
        nargs=2,
        type=given("--launch"),
        metavar=("PACKAGE", "FILE"),
        help="start the node under test by `ros2 launch PACKAGE FILE` (needs ros2 with its "
        "launch verb, from a sourced ROS 2; --workspace DIR finds the package), the harness's "
        "parameters passed as the launch arguments the file declares; instead of "
        "--node/--package (see docs/launch_files.md)",
    )


def check_launch(args: argparse.Namespace, console: Console) -> None:
    """`--launch`: refused with options it cannot go with; its file found and read now;
    where `ros2 launch` is missing, the file's problems printed, then ConfigError."""
    if not getattr(args, "launch", None):
        return
    package, file = args.launch
    if not link_kind(args.link).launches:
        launched = either([name for name in link_names() if link_kind(name).launches])
        raise ConfigError(f"--launch needs --link {launched}, not {args.link}")
    if args.node or args.package or args.executable:
        raise ConfigError("--launch starts the node itself: drop --node/--package/--executable")
    if getattr(args, "watch", False):
        raise ConfigError("--launch cannot go with --watch: use --package/--executable to watch")
    from harness.launch_files.launch_command import (
        find_launch_file,
        missing_message,
        ros2_launch_missing,
    )
    from harness.launch_files.run_check import LaunchCheck
    from harness.report.console_text import print_safe

    launched = find_launch_file(package, file, args.workspace)
    missing = ros2_launch_missing()
    if missing is None:
        return
    check = LaunchCheck.for_run(package, None, args.workspace, launched=launched.path.name)
    for note in check.static if check is not None else ():
        print_safe(console, f"note: {note}", style="yellow")
    raise ConfigError(missing_message(package, file, missing))
