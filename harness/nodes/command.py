"""Which command starts the node under test, and with which arguments: a user's command
line, a workspace's package/executable as ``ros2 run`` finds it, or the bundled
reference (``python -m``, which the fork server may start)."""

from __future__ import annotations

import os
import shlex
import shutil
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from harness.errors import OptionError
from harness.nodes.colcon_hooks import hook_environment
from harness.nodes.setup_problems import is_python

AMENT_MARKERS = Path("share/ament_index/resource_index/packages")


@dataclass(frozen=True)
class NodeCommand:
    """How to start a node: argv before --ros-args, extra environment, a name for messages."""

    argv: tuple[str, ...]
    env: dict[str, str] = field(default_factory=dict)
    description: str = ""
    # Set when argv is ``sys.executable -m MODULE``: the fork server may start it.
    module: str | None = None
    # Set for ``ros2 launch PACKAGE FILE``: the launch arguments the file declares, which
    # take the node's parameters (``node_arguments``).
    launch_arguments: frozenset[str] | None = None


def reference_node() -> NodeCommand:
    """The bundled reference solution, runnable without colcon."""
    module = "harness.reference.lidar_node"
    return NodeCommand(
        (sys.executable, "-m", module),
        description="the bundled reference node (fossbot_lidar_processing)",
        module=module,
    )


def split_command(command: str, *, option: str = "node") -> list[str]:
    """A user's command line split like a shell does, never empty; OptionError names
    `option`, the key of the option that gave it."""
    try:
        argv = shlex.split(command)
    except ValueError as err:
        raise OptionError.saying(option, f"{command!r}: {err}") from None
    if not argv:
        raise OptionError(option, f"{{{option}}}: the command is empty")
    return argv


def shell_node(command: str, *, option: str = "node") -> NodeCommand:
    """A user's command line, e.g. ``python3 my_node.py``, split like a shell does;
    errors name `option`, the key of the option that gave it."""
    argv = split_command(command, option=option)
    program = argv[0]
    if program.endswith(".py") and Path(program).is_file():  # as grade runs a script
        argv = [sys.executable, *argv]
        program = argv[0]
    if "/" in program:
        if not Path(program).is_file():
            raise OptionError.saying(option, f"{command!r}: no such file {program}")
        if not os.access(program, os.X_OK):
            raise OptionError.saying(option, f"{command!r}: {program} is not executable")
    elif shutil.which(program) is None:
        raise OptionError.saying(option, f"{command!r}: {program!r} not found on PATH")
    script = python_script_of(argv)
    if script is not None and not Path(script).is_file():
        raise OptionError.saying(option, f"{command!r}: no such script {script}")
    return NodeCommand(tuple(argv), description=command)


def python_script_of(argv: Sequence[str]) -> str | None:
    """The script a Python command line runs (None for -m, -c or no script)."""
    if not is_python(argv[0]):
        return None
    args = iter(argv[1:])
    for arg in args:
        if arg.startswith(("-m", "-c")):
            return None
        if arg in ("-W", "-X"):  # options that take a value
            next(args, None)
        elif not arg.startswith("-"):
            return arg
    return None


def install_prefixes(install: Path) -> list[Path]:
    """Install prefixes of a colcon install folder (isolated or merged layout)."""
    if (install / AMENT_MARKERS).is_dir():
        return [install]
    return sorted(p for p in install.iterdir() if (p / AMENT_MARKERS).is_dir())


def _site_packages(prefix: Path) -> list[Path]:
    return sorted(prefix.glob("lib/python3*/site-packages")) + sorted(
        prefix.glob("local/lib/python3*/dist-packages")
    )


def _env_for(prefixes: list[Path]) -> dict[str, str]:
    """What sourcing the workspace's setup script would add, for these prefixes."""

    def joined(name: str, parts: list[Path]) -> str:
        old = os.environ.get(name, "")
        return os.pathsep.join([*(str(p) for p in parts), *([old] if old else [])])

    return {
        "AMENT_PREFIX_PATH": joined("AMENT_PREFIX_PATH", prefixes),
        "PYTHONPATH": joined("PYTHONPATH", [s for p in prefixes for s in _site_packages(p)]),
        "PATH": joined("PATH", [p / "bin" for p in prefixes if (p / "bin").is_dir()]),
        "LD_LIBRARY_PATH": joined("LD_LIBRARY_PATH", [p / "lib" for p in prefixes]),
    }


def workspace_environment(prefixes: list[Path]) -> dict[str, str]:
    """What sourcing the workspace would set: its folders' usual places, then what its
    packages' colcon hooks add (a --symlink-install build's source links among them)."""
    env = _env_for(prefixes)
    return {**env, **hook_environment(prefixes, {**os.environ, **env})}


def package_node(package: str, executable: str, workspace: str | None) -> NodeCommand:
    """Find `executable` of `package` as ``ros2 run`` does: through the ament index."""
    if workspace is not None:
        root = Path(workspace)
        if not root.is_dir():
            raise OptionError.saying("workspace", f"{workspace}: no such folder")
        install = root / "install" if (root / "install").is_dir() else root
        prefixes = install_prefixes(install)
        where = f"workspace {install}"
        if not prefixes:
            raise OptionError.saying(
                "workspace",
                f"{workspace}: no colcon install folder with packages "
                f"(run 'colcon build' in {root} first)",
            )
    else:
        prefixes = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        where = "AMENT_PREFIX_PATH"
        if not prefixes:
            raise OptionError(
                "package", "{package} needs {workspace} DIR (or a sourced ROS 2 / workspace)"
            )
    owner = next((p for p in prefixes if (p / AMENT_MARKERS / package).is_file()), None)
    if owner is None:
        indexes = [p / AMENT_MARKERS for p in prefixes if (p / AMENT_MARKERS).is_dir()]
        found = sorted({marker.name for index in indexes for marker in index.iterdir()})
        listed = ", ".join(found[:20]) or "none"
        raise OptionError.saying("package", f"{package}: not found in {where} (packages: {listed})")
    program = owner / "lib" / package / executable
    if not program.is_file():
        folder = owner / "lib" / package
        there = sorted(p.name for p in folder.glob("*")) if folder.is_dir() else []
        raise OptionError.saying(
            "executable",
            f"{executable}: not in package {package} (executables: {', '.join(there) or 'none'})",
        )
    env = workspace_environment(prefixes) if workspace is not None else {}
    return NodeCommand((str(program),), env, f"{package}/{executable} from {where}")


def ros_arguments(params: tuple[str, ...], *, use_sim_time: bool = True) -> list[str]:
    """``--ros-args -p use_sim_time:=true -p NAME:=VALUE ...`` (the user's items verbatim)."""
    head = ["--ros-args", "-p", "use_sim_time:=true"] if use_sim_time else ["--ros-args"]
    return [*head, *(word for item in params for word in ("-p", item))]


def node_arguments(
    command: NodeCommand, params: tuple[str, ...], *, use_sim_time: bool = True
) -> list[str]:
    """The parameters as `command` takes them: after ``--ros-args``, or for ``ros2
    launch`` as NAME:=VALUE launch arguments, those its file declares."""
    if command.launch_arguments is None:
        return ros_arguments(params, use_sim_time=use_sim_time)
    items = ("use_sim_time:=true",) * use_sim_time + params
    return [item for item in items if item.split(":=", 1)[0] in command.launch_arguments]
