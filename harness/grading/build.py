"""colcon build of one student's packages into a scratch workspace, and its first real error.

The student's folder is only read: colcon is pointed at their package
folders with ``--base-paths`` and writes build/, install/ and log/ under the
grader's output folder. The build is bounded in time and in log size.
"""

from __future__ import annotations

import re
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from harness.errors import ConfigError
from harness.grading.discover import Student
from harness.grading.process import Finished, StopFlag, run_bounded
from harness.sandbox.limits import SandboxLimits
from harness.sandbox.refusals import refusal_of
from harness.sandbox.student import sandboxed_build

__all__ = ["BuildResult", "build_student", "build_error", "colcon_command"]

AMENT_MARKERS = Path("share/ament_index/resource_index/packages")
MAX_LOG_BYTES = 20 * 1024 * 1024
EVENT_HANDLERS = ("console_direct+", "console_stderr-", "desktop_notification-", "status-")

# The line a student should read first, most telling kind first.
_PY_ERROR = re.compile(r"^(?:[A-Za-z_][\w.]*\.)?([A-Z]\w*(?:Error|Exception|Exit))\b(?::\s?(.*))?$")
_PY_WHERE = re.compile(r'^\s*File "([^"]+)", line (\d+)')
_WRAPPERS = {"CalledProcessError"}  # colcon's own report that a setup.py step failed
_OTHER_ERRORS = (
    re.compile(r"^CMake Error.*?:\s*(.+)$"),
    re.compile(r"^(?:\[[\d.]+s\]\s*)?ERROR:colcon[\w.]*:(.+)$"),
    re.compile(r"^error: (.+)$"),
    re.compile(r"^(.*\berror\b.*)$", re.IGNORECASE),
)
_FAILED = re.compile(r"^Failed\s+<<<\s+(\S+)\s+\[(.*)\]")


@dataclass(frozen=True)
class BuildResult:
    """A student's build: where it installed, how long it took, and why it failed."""

    workspace: Path  # holds install/ (what --workspace takes)
    wall_s: float
    error: str | None = None  # "did not build: <this>"

    @property
    def ok(self) -> bool:
        return self.error is None


def colcon_executable() -> str:
    """colcon beside this Python (the venv), else on PATH; ConfigError if it is missing."""
    beside = Path(sys.executable).parent / "colcon"
    found = str(beside) if beside.is_file() else shutil.which("colcon")
    if found is None:
        raise ConfigError(
            "colcon not found: pip install colcon-common-extensions (or source ROS 2 Jazzy)"
        )
    return found


def colcon_command(student: Student, workspace: Path, colcon: str) -> list[str]:
    """`colcon build` of the student's package folders, every output under `workspace`."""
    return [
        colcon,
        "--log-base",
        str(workspace / "log"),
        "build",
        "--event-handlers",
        *EVENT_HANDLERS,
        "--base-paths",
        *(str(p.resolve()) for p in student.base_paths),
        "--build-base",
        str(workspace / "build"),
        "--install-base",
        str(workspace / "install"),
    ]


def _python_error(lines: list[str]) -> str | None:
    """The first exception a traceback ended with that is not colcon's wrapper, with its place."""
    for i, line in enumerate(lines):
        match = _PY_ERROR.match(line)
        if not match or match.group(1) in _WRAPPERS:
            continue
        kind, detail = match.group(1), (match.group(2) or "").strip()
        where = ""
        for previous in reversed(lines[max(0, i - 12) : i]):
            place = _PY_WHERE.match(previous)
            if place:
                name = Path(place.group(1)).name
                # setup.py runs through exec(): its frames are "<string>"
                name = "setup.py" if name == "<string>" else name
                where = f"{name} line {place.group(2)}: "
                break
        return f"{where}{kind}: {detail}" if detail else f"{where}{kind}"
    return None


def _first_match(pattern: re.Pattern[str], lines: list[str]) -> str | None:
    """The pattern's group in the first line it matches, with a list that follows a colon."""
    for i, line in enumerate(lines):
        match = pattern.match(line)
        if match:
            found = match.group(1).strip()
            if found.endswith(":"):  # e.g. colcon's "Duplicate package names ...:" then "- ..."
                items = [x.strip() for x in lines[i + 1 : i + 7] if x.lstrip().startswith("- ")]
                found = " ".join([found, *items])
            return found
    return None


def build_error(log_text: str, *, hide: tuple[Path, ...] = ()) -> str:
    """The line of a failed colcon log that says what is wrong, paths made short."""
    lines = [line.rstrip() for line in log_text.splitlines()]
    found = _python_error(lines)
    if found is None:
        for pattern in _OTHER_ERRORS:
            found = _first_match(pattern, lines)
            if found:
                break
    if found is None:
        failed = next((m for m in map(_FAILED.match, lines) if m), None)
        found = f"colcon: {failed.group(1)} failed ({failed.group(2)})" if failed else None
    if found is None:
        found = next((line for line in reversed(lines) if line.strip()), "colcon failed")
    for folder in hide:  # paths inside the student's folder, relative; the folder, by name
        for path in dict.fromkeys((str(folder.resolve()), str(folder))):
            found = found.replace(f"{path}/", "").replace(path, folder.name)
    if "CMakeLists.txt" in found:  # colcon took it for ament_cmake, the default build type
        found += " (does package.xml say <build_type>ament_python</build_type>?)"
    return found


def installed_packages(install: Path) -> dict[str, Path]:
    """Package name -> install prefix, for an isolated or merged colcon install folder."""
    prefixes = [install] if (install / AMENT_MARKERS).is_dir() else []
    if install.is_dir() and not prefixes:
        prefixes = sorted(p for p in install.iterdir() if (p / AMENT_MARKERS).is_dir())
    return {m.name: prefix for prefix in prefixes for m in (prefix / AMENT_MARKERS).iterdir()}


def check_installed(install: Path, package: str, executable: str) -> str | None:
    """Why the build does not give the lab's node, or None when it does."""
    packages = installed_packages(install)
    if package not in packages:
        built = ", ".join(sorted(packages)) or "no ROS 2 package"
        return f"package {package} was not built (built: {built})"
    lib = packages[package] / "lib" / package
    if not (lib / executable).is_file():
        there = ", ".join(sorted(p.name for p in lib.iterdir())) if lib.is_dir() else "none"
        return f"package {package} has no executable {executable} (executables: {there})"
    return None


def _outcome_error(finished: Finished, log: Path, timeout: float) -> str | None:
    if finished.start_error:
        return finished.start_error
    if finished.timed_out:
        return f"the build took longer than {timeout:g} s (stopped)"
    if finished.flooded:
        return f"the build wrote more than {MAX_LOG_BYTES // 2**20} MB of output (stopped)"
    if finished.cancelled:
        return "interrupted"
    return None


def build_student(
    student: Student,
    workspace: Path,
    *,
    package: str,
    executable: str,
    log: Path,
    timeout: float,
    cancel: StopFlag | None = None,
    sandbox: SandboxLimits | None = None,
) -> BuildResult:
    """Build `student` into `workspace` (wiped first), logging colcon's output to `log`;
    in a sandbox under `sandbox`'s limits unless it is None."""
    shutil.rmtree(workspace, ignore_errors=True)
    workspace.mkdir(parents=True)
    command = colcon_command(student, workspace, colcon_executable())
    if sandbox is not None:
        command = sandboxed_build(command, student.folder, workspace, sandbox)
    finished = run_bounded(
        command,
        log=log,
        timeout=timeout,
        max_log_bytes=MAX_LOG_BYTES,
        cwd=workspace,
        cancel=cancel,
    )
    error = _outcome_error(finished, log, timeout)
    if error is None and finished.returncode != 0:
        text = log.read_text(encoding="utf-8", errors="replace")
        error = build_error(text, hide=(student.folder, workspace))
        refused = None if sandbox is None else refusal_of(text, sandbox)
        error += f" ({refused})" if refused else ""
    if error is None:
        error = check_installed(workspace / "install", package, executable)
    return BuildResult(workspace, finished.wall_s, error)
