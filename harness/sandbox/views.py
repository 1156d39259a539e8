"""What each sandbox of a student shows: the system and the harness read-only, and
only the folders that step needs.

- The build: the student's folder (read-only) and its colcon folder (writable).
- The judging run: also the scenario files and the student's output folders;
  no other student, no class folder, no grading file, no grades.
- The node, nested in the judging run's sandbox (same network and PIDs): its
  own build or script folder only, never the scenarios or any report.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path

from harness.nodes.sandbox_prefix import NODE_SANDBOX_ENV
from harness.sandbox.bwrap import View

__all__ = ["build_view", "node_view", "run_view", "sandbox_env", "system_paths"]

SYSTEM = ("/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32", "/etc", "/opt")
# What the sandboxed environment keeps of the grader's: these names, and names with these
# beginnings.
KEPT_NAMES = ("PATH", "LANG", "LANGUAGE", "TZ", "TERM", "VIRTUAL_ENV", "LD_LIBRARY_PATH")
KEPT_PREFIXES = ("LC_", "PYTHON", "ROS_", "RMW_", "RCUTILS_", "FASTRTPS_", "FASTDDS_")
KEPT_PREFIXES += ("CYCLONEDDS_", "AMENT_", "COLCON_", "CMAKE_PREFIX_PATH")


def _existing(paths: Iterable[str | Path]) -> list[str]:
    texts = (os.path.abspath(str(path)) for path in paths)
    return list(dict.fromkeys(text for text in texts if os.path.lexists(text)))


@functools.cache
def system_paths() -> tuple[tuple[str, ...], dict[str, str]]:
    """(folders, symlinks) of the system a sandbox shows read-only: the OS, this Python
    and its packages, the harness, ROS 2 where it is sourced. Looked up once a process
    (every student's three sandboxes show the same)."""
    import harness

    links = {p: os.readlink(p) for p in SYSTEM if os.path.islink(p)}
    folders = [p for p in SYSTEM if p not in links]
    folders += [sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix]
    package = Path(harness.__file__).resolve().parent
    folders.append(str(package))
    # In a source tree, some subpackages are links out of it (robot_models, scenarios).
    folders += [str(p.resolve()) for p in package.iterdir() if p.is_symlink()]
    # Packages installed elsewhere (site-packages of an editable install, a user site).
    folders += [p for p in sys.path if p and ("-packages" in p) and os.path.isdir(p)]
    for name in ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "LD_LIBRARY_PATH"):
        folders += [p for p in os.environ.get(name, "").split(os.pathsep) if p]
    # The interpreter a venv links to, wherever it lives.
    folders.append(str(Path(os.path.realpath(sys.executable)).parent.parent))
    return tuple(_existing(folders)), links


def sandbox_env(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """The grader's environment without anything of its own (tokens, paths of its
    folders): only what Python, ROS 2 and DDS read."""
    kept = {n: v for n, v in os.environ.items() if n in KEPT_NAMES or n.startswith(KEPT_PREFIXES)}
    kept["PYTHONUNBUFFERED"] = "1"
    return {**kept, **(extra or {})}


def _view(read_only: Iterable[str | Path], writable: Iterable[str | Path], **how: object) -> View:
    system, links = system_paths()
    return View(
        read_only=(*system, *_existing(read_only)),
        writable=tuple(_existing(writable)),
        links=links,
        **how,  # type: ignore[arg-type]
    )


def build_view(student_folder: Path, colcon_folder: Path) -> View:
    """colcon: reads the student's folder, writes build/, install/ and log/."""
    return _view([student_folder.resolve()], [colcon_folder.resolve()], env=sandbox_env())


def run_view(
    node_files: Iterable[Path],
    scenario_files: Iterable[Path],
    outputs: Iterable[Path],
    env: Mapping[str, str] | None = None,
) -> View:
    """The judging process: the node's files (to start it), the scenario files, and the
    student's output folders (report, results); `env` added to its environment."""
    read = [p.resolve() for p in (*node_files, *scenario_files)]
    return _view(read, [p.resolve() for p in outputs], env=sandbox_env(env))


def node_view(node_files: Iterable[Path]) -> View:
    """The node, inside the judging run's sandbox: its own files only; the environment
    the judging process gives it (already the sandbox's)."""
    nested = {"own_network": False, "own_pids": False, "share_shm": True, "keep_env": True}
    return _view([p.resolve() for p in node_files], [], **nested, unset=(NODE_SANDBOX_ENV,))
