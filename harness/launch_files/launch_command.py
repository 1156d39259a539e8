"""`run --launch PACKAGE FILE`: the node under test started by ``ros2 launch``.

``ros2 launch`` is not on the package index, so where no ROS 2 is sourced --launch is
a usage error saying what to do instead. The harness's parameters reach the node as
the launch arguments the file declares."""

from __future__ import annotations

import functools
import shutil
import subprocess
from pathlib import Path

from harness.errors import ConfigError, OptionError
from harness.launch_files.entries import LaunchFile
from harness.launch_files.finding import package_launch_files, workspace_of
from harness.launch_files.reading import read_launch_file
from harness.nodes.command import NodeCommand, workspace_environment
from harness.option_names import named, worded

__all__ = ["find_launch_file", "launch_node", "ros2_launch_missing"]

ROS2_PROGRAM = "ros2"  # ros2cli, whose launch verb starts the node
HELP_TIMEOUT_S = 30.0  # `ros2 launch --help` (ros2cli loads its verbs: a second or two)
INSTEAD = (  # worded when shown, as the caller names the options
    "source a ROS 2 installation that has it (e.g. `. /opt/ros/jazzy/setup.bash`), or leave "
    "{launch} out: with {workspace} DIR {package} P {executable} E the harness still reads "
    "the package's launch files and checks them against the running node"
)


@functools.lru_cache(maxsize=1)
def ros2_launch_missing() -> str | None:
    """Why `ros2 launch` cannot run here, or None when it can (asked once a process)."""
    program = shutil.which(ROS2_PROGRAM)
    if program is None:
        return "no ros2 on PATH"
    try:
        command = [program, "launch", "--help"]
        done = subprocess.run(command, capture_output=True, timeout=HELP_TIMEOUT_S, check=False)
    except (OSError, subprocess.TimeoutExpired) as err:
        return f"`ros2 launch --help` failed: {err}"
    if done.returncode != 0:
        return "ros2 has no launch verb (ros2launch is not installed)"
    return None


def missing_message(package: str, file: str, reason: str) -> str:
    launch = f"{named('launch')} {package} {file}"
    return f"{launch}: `ros2 launch` is not installed here ({reason}); {worded(INSTEAD)}"


def find_launch_file(package: str, file: str, workspace: str | None) -> LaunchFile:
    """The launch file `ros2 launch PACKAGE FILE` starts, read (not run); ConfigError
    when the package has none of that name."""
    option = f"{package} {file}"
    found = package_launch_files(package, workspace_of(workspace))
    name = Path(file).name
    match = next((path for path, _ in found.files if path.name == name), None)
    if match is None:
        listed = ", ".join(path.name for path, _ in found.files) or "none found"
        raise OptionError.saying(
            "launch", f"{option}: {package} has no launch file {name} (its launch files: {listed})"
        )
    shown = next(s for path, s in found.files if path == match)
    read = read_launch_file(match, shown)
    if read is None:
        raise OptionError.saying(
            "launch", f"{option}: {shown} is not a launch file (no launch description in it)"
        )
    return read


def launch_node(package: str, file: str, workspace: str | None) -> NodeCommand:
    """``ros2 launch PACKAGE FILE`` as the node's command, in the workspace's environment."""
    missing = ros2_launch_missing()
    if missing is not None:
        raise ConfigError(missing_message(package, file, missing))
    launched = find_launch_file(package, file, workspace)
    prefixes = list(workspace_of(workspace).prefixes) if workspace is not None else []
    env = workspace_environment(prefixes) if prefixes else {}
    return NodeCommand(
        (shutil.which(ROS2_PROGRAM) or ROS2_PROGRAM, "launch", package, Path(file).name),
        env,
        f"ros2 launch {package} {Path(file).name}",
        launch_arguments=frozenset(launched.arguments),
    )
