"""The node under test as a separate process: resolve, start, watch, stop, reap.

The node is started the way a user would start it (a shell command, a
colcon workspace's package/executable as ``ros2 run`` finds it, or the
bundled reference node), with ``--ros-args`` appended. It runs in its own
process group so that stopping it also stops anything it started, and its
output goes to files so that a chatty node can never block on a full pipe.
"""

from __future__ import annotations

import atexit
import os
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from harness.errors import ConfigError

AMENT_MARKERS = Path("share/ament_index/resource_index/packages")
STOP_GRACE_S = 3.0  # per signal: SIGINT, then SIGTERM, then SIGKILL
TAIL_BYTES = 8192


@dataclass(frozen=True)
class NodeCommand:
    """How to start a node: argv before --ros-args, extra environment, a name for messages."""

    argv: tuple[str, ...]
    env: dict[str, str] = field(default_factory=dict)
    description: str = ""


def reference_node() -> NodeCommand:
    """The bundled reference solution, runnable without colcon."""
    return NodeCommand(
        (sys.executable, "-m", "harness.reference.lidar_node"),
        description="the bundled reference node (fossbot_lidar_processing)",
    )


def shell_node(command: str) -> NodeCommand:
    """A user's command line, e.g. ``python3 my_node.py``, split like a shell does."""
    try:
        argv = shlex.split(command)
    except ValueError as err:
        raise ConfigError(f"--node {command!r}: {err}") from None
    if not argv:
        raise ConfigError("--node: the command is empty")
    program = argv[0]
    if "/" in program:
        if not Path(program).is_file():
            raise ConfigError(f"--node {command!r}: no such file {program}")
        if not os.access(program, os.X_OK):
            raise ConfigError(f"--node {command!r}: {program} is not executable")
    elif shutil.which(program) is None:
        raise ConfigError(f"--node {command!r}: {program!r} not found on PATH")
    return NodeCommand(tuple(argv), description=command)


def _prefixes(install: Path) -> list[Path]:
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


def package_node(package: str, executable: str, workspace: str | None) -> NodeCommand:
    """Find `executable` of `package` as ``ros2 run`` does: through the ament index."""
    if workspace is not None:
        root = Path(workspace)
        if not root.is_dir():
            raise ConfigError(f"--workspace {workspace}: no such folder")
        install = root / "install" if (root / "install").is_dir() else root
        prefixes = _prefixes(install)
        where = f"workspace {install}"
        if not prefixes:
            raise ConfigError(
                f"--workspace {workspace}: no colcon install folder with packages "
                f"(run 'colcon build' in {root} first)"
            )
    else:
        prefixes = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        where = "AMENT_PREFIX_PATH"
        if not prefixes:
            raise ConfigError("--package needs --workspace DIR (or a sourced ROS 2 / workspace)")
    owner = next((p for p in prefixes if (p / AMENT_MARKERS / package).is_file()), None)
    if owner is None:
        found = sorted(
            {
                m.name
                for p in prefixes
                if (p / AMENT_MARKERS).is_dir()
                for m in (p / AMENT_MARKERS).iterdir()
            }
        )
        listed = ", ".join(found[:20]) or "none"
        raise ConfigError(f"--package {package}: not found in {where} (packages: {listed})")
    program = owner / "lib" / package / executable
    if not program.is_file():
        there = (
            sorted(p.name for p in (owner / "lib" / package).glob("*"))
            if (owner / "lib" / package).is_dir()
            else []
        )
        raise ConfigError(
            f"--executable {executable}: not in package {package} "
            f"(executables: {', '.join(there) or 'none'})"
        )
    env = _env_for(prefixes) if workspace is not None else {}
    return NodeCommand((str(program),), env, f"{package}/{executable} from {where}")


def ros_arguments(params: tuple[str, ...], *, use_sim_time: bool = True) -> list[str]:
    """``--ros-args -p use_sim_time:=true -p NAME:=VALUE ...`` (the user's items verbatim)."""
    args = ["--ros-args"]
    if use_sim_time:
        args += ["-p", "use_sim_time:=true"]
    for item in params:
        args += ["-p", item]
    return args


_LIVE: set[NodeProcess] = set()


def _stop_all_at_exit() -> None:
    for process in list(_LIVE):
        process.stop()


atexit.register(_stop_all_at_exit)


def _load_prctl():
    """libc's prctl, loaded once here: the child must not dlopen between fork and exec."""
    try:
        import ctypes

        return ctypes.CDLL("libc.so.6", use_errno=True).prctl
    except (OSError, AttributeError):
        return None


_PRCTL = _load_prctl()
PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:  # runs in the child between fork and exec
    """Ask Linux to SIGTERM the node if the harness dies without cleaning up."""
    if _PRCTL is not None:
        _PRCTL(PR_SET_PDEATHSIG, signal.SIGTERM)


class NodeProcess:
    """One running node under test."""

    def __init__(self, command: NodeCommand, args: list[str], env: dict[str, str]) -> None:
        self.command = command
        self.argv = [*command.argv, *args]
        self.env = {**os.environ, **command.env, **env, "PYTHONUNBUFFERED": "1"}
        self._dir = tempfile.TemporaryDirectory(prefix="fossbot-hil-node-")
        self.stdout_path = Path(self._dir.name) / "stdout.log"
        self.stderr_path = Path(self._dir.name) / "stderr.log"
        self._popen: subprocess.Popen[bytes] | None = None
        self.started_at = 0.0

    def start(self) -> None:
        with open(self.stdout_path, "wb") as out, open(self.stderr_path, "wb") as err:
            try:
                self._popen = subprocess.Popen(
                    self.argv,
                    stdin=subprocess.DEVNULL,
                    stdout=out,
                    stderr=err,
                    env=self.env,
                    start_new_session=True,
                    preexec_fn=_die_with_parent,
                )
            except OSError as error:
                raise ConfigError(f"cannot start {self.command.description}: {error}") from None
        self.started_at = time.monotonic()
        _LIVE.add(self)

    @property
    def pid(self) -> int | None:
        return self._popen.pid if self._popen else None

    def returncode(self) -> int | None:
        """None while running; the exit code (negative: killed by that signal) after."""
        return self._popen.poll() if self._popen else None

    def tail(self, which: str = "stderr", lines: int = 15) -> str:
        """The last lines the node wrote on stdout or stderr."""
        path = self.stderr_path if which == "stderr" else self.stdout_path
        try:
            with open(path, "rb") as handle:
                handle.seek(max(0, path.stat().st_size - TAIL_BYTES))
                text = handle.read().decode("utf-8", "replace")
        except OSError:
            return ""
        return "\n".join(text.rstrip().splitlines()[-lines:])

    def exit_summary(self, when: str = "") -> str:
        """`exited with code 1 <when>; last stderr: ...` for failure explanations."""
        code = self.returncode()
        if code is None:
            return "still running"
        how = f"was killed by signal {-code}" if code < 0 else f"exited with code {code}"
        last = self.tail("stderr", 3).replace("\n", " | ")
        return " ".join(filter(None, [how, when])) + (f"; last stderr: {last}" if last else "")

    def _signal_group(self, sig: int) -> None:
        assert self._popen is not None
        try:
            os.killpg(self._popen.pid, sig)
        except (ProcessLookupError, PermissionError):
            pass

    def stop(self) -> int | None:
        """SIGINT, then SIGTERM, then SIGKILL (each after a bounded wait); reap all."""
        if self._popen is None:
            return None
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            if self._popen.poll() is not None:
                break
            self._signal_group(sig)
            try:
                self._popen.wait(timeout=STOP_GRACE_S)
            except subprocess.TimeoutExpired:
                continue
        self._signal_group(signal.SIGKILL)  # children the node left behind
        _LIVE.discard(self)
        return self._popen.wait()

    def cleanup(self) -> None:
        """Stop and remove the log files (after their tails were read)."""
        self.stop()
        self._dir.cleanup()
