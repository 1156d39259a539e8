"""`run --launch PACKAGE FILE`: the node started by ``ros2 launch``, where that is installed.

Where ``ros2 launch`` is missing (it is not on the package index), the file
is still read and its problems printed before the exit 2 (docs/launch_files.md).
"""

from __future__ import annotations

import argparse

from rich.console import Console

from harness.commands.arguments import add_row, not_empty, request_of
from harness.errors import ConfigError

__all__ = ["add_launch_option", "check_launch"]


def add_launch_option(parser: argparse.ArgumentParser) -> None:
    add_row(parser, "launch", nargs=2, type=not_empty, metavar=("PACKAGE", "FILE"))


def check_launch(args: argparse.Namespace, console: Console) -> None:
    """`--launch`: refused with options it cannot go with; its file found and read now;
    where `ros2 launch` is missing, the file's problems printed, then ConfigError."""
    if not getattr(args, "launch", None):
        return
    package, file = args.launch
    request_of(args)  # with a link that launches, and no other way to start the node
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
