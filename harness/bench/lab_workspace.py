"""The lab's node package in a colcon workspace of its own, as a student's workspace holds it.

The bench times ``fossbot-hil run --workspace`` against the bundled node, so
the workspace is what a student has after following the lab. It needs a
source checkout and colcon; without either the bench says so instead of
timing something else. The build is timed apart: a student builds once.
"""

from __future__ import annotations

import contextlib
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import harness
from harness.bench.suite_commands import cli_args
from harness.errors import HarnessError
from harness.links.base import LinkOptions
from harness.nodes.process_group import signal_group, wait_group_gone

LAB_PACKAGE = "fossbot_lidar_processing"  # as the lab names them (FACTS.md)
LAB_EXECUTABLE = "fossbot_lidar_node"
BUILD_TIMEOUT_S = 300.0  # a build of the lab's package takes about 4 s on 2 cores
KILL_WAIT_S = 5.0
# The build's output in its log (for the reason it failed); no desktop notifications.
EVENT_HANDLERS = ("console_direct+", "console_stderr-", "desktop_notification-", "status-")
# What a checkout may hold next to the package's sources that a student's copy would not.
_NOT_SOURCES = shutil.ignore_patterns(
    "__pycache__", "*.egg-info", "build", "install", "log", ".pytest_cache"
)
_PY_ERROR = re.compile(r"^\s*(?!CalledProcessError)([A-Z]\w*(?:Error|Exception)\b.*)$")


@dataclass(frozen=True)
class LabWorkspace:
    """A built workspace: its folder (holding install/), and how long `colcon build` took."""

    root: Path
    build_s: float
    package: str = LAB_PACKAGE
    executable: str = LAB_EXECUTABLE

    def run_args(self) -> list[str]:
        """The options that make ``fossbot-hil run`` start this workspace's node."""
        return cli_args(workspace=str(self.root), package=self.package, executable=self.executable)

    def link_options(self) -> LinkOptions:
        """The same node for ``runner.run_suite`` in this process."""
        return LinkOptions(
            workspace=str(self.root), package=self.package, executable=self.executable
        )


def lab_package_source(harness_dir: Path | None = None) -> Path:
    """node/fossbot_lidar_processing of the checkout the harness (`harness_dir`) runs
    from, else of the working folder; an installed wheel run elsewhere has neither."""
    here = (harness_dir or Path(harness.__file__).parent).resolve()
    for root in (here.parent, Path.cwd()):
        source = root / "node" / LAB_PACKAGE
        if (source / "package.xml").is_file() and (source / "setup.py").is_file():
            return source
    raise HarnessError(
        f"the harness at {here} is installed without its repository (no node/{LAB_PACKAGE} "
        "beside it or in the working folder): the workspace-node figures need a source "
        "checkout (run the bench there, or pip install -e)"
    )


def colcon_program() -> str:
    """colcon beside this Python (the venv), else on PATH; HarnessError naming the extra."""
    beside = Path(sys.executable).parent / "colcon"
    found = str(beside) if beside.is_file() else shutil.which("colcon")
    if found is None:
        raise HarnessError(
            "colcon not found: the workspace-node figures build the lab's package with it "
            "(pip install -e '.[test]', or colcon-common-extensions, or source ROS 2 Jazzy)"
        )
    return found


def build_lab_workspace(
    root: Path, source: Path, colcon: str, *, timeout: float = BUILD_TIMEOUT_S
) -> LabWorkspace:
    """Copy `source` into `root`/src and run `colcon build` in `root` (bounded)."""
    shutil.copytree(source, root / "src" / source.name, ignore=_NOT_SOURCES)
    log = root / "colcon-build.log"
    with open(log, "wb") as out:
        started = time.perf_counter()
        popen = subprocess.Popen(
            [colcon, "build", "--event-handlers", *EVENT_HANDLERS],
            cwd=root,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its own group: a timeout stops setup.py too
        )
        try:
            returncode = popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            _kill(popen)
            raise HarnessError(
                f"colcon build of {source.name} took longer than {timeout:g} s (stopped)"
            ) from None
        except BaseException:  # Ctrl-C: no build left behind
            _kill(popen)
            raise
        seconds = time.perf_counter() - started
    if returncode != 0:
        text = log.read_text(encoding="utf-8", errors="replace")
        raise HarnessError(f"colcon build of {source.name} failed: {_reason(text)}")
    program = root / "install" / LAB_PACKAGE / "lib" / LAB_PACKAGE / LAB_EXECUTABLE
    if not program.is_file():
        raise HarnessError(f"colcon build of {source.name} did not install {program}")
    return LabWorkspace(root, seconds)


def _kill(popen: subprocess.Popen[bytes]) -> None:
    """Stop the build's whole process group, bounded."""
    signal_group(popen.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):  # unkillable (D state): no hang
        popen.wait(timeout=KILL_WAIT_S)
    wait_group_gone(popen.pid, KILL_WAIT_S)


def _reason(log_text: str) -> str:
    """The exception a failed build ended with, else the log's last lines."""
    lines = [line.strip() for line in log_text.splitlines() if line.strip()]
    found = next((m.group(1) for m in map(_PY_ERROR.match, lines) if m), None)
    return found or " / ".join(lines[-3:]) or "colcon wrote nothing"
