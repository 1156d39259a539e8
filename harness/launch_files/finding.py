"""Which launch files a package has: its source ``launch/`` folder, else the installed copy.

Notes point at the source (what the student edits); a source file missing from the
installed copy (what ``ros2 launch`` runs), or different, is said too."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from harness.launch_files.reading import is_launch_name
from harness.nodes.command import AMENT_MARKERS, install_prefixes
from harness.nodes.package_folder import find_package

__all__ = ["Found", "Workspace", "install_note", "package_launch_files", "workspace_of"]

MAX_FILES = 50  # launch files read per package, at most


@dataclass(frozen=True)
class Workspace:
    """Where packages are: the workspace's root (None for a sourced install, or an
    install folder given as the workspace) and its install prefixes."""

    root: Path | None
    prefixes: tuple[Path, ...]

    def owner(self, package: str) -> Path | None:
        """The prefix that installs `package`, if any."""
        return next((p for p in self.prefixes if (p / AMENT_MARKERS / package).is_file()), None)


def workspace_of(workspace: str | None) -> Workspace:
    """The --workspace folder (its install/, or the folder itself), else the
    environment's AMENT_PREFIX_PATH; a folder that is not there has no prefixes."""
    if workspace is None:
        found = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        return Workspace(None, tuple(found))
    root = Path(workspace).expanduser()
    install = root / "install" if (root / "install").is_dir() else root
    try:
        prefixes = install_prefixes(install)
    except OSError:
        prefixes = []
    return Workspace(root if install != root else None, tuple(prefixes))


@dataclass(frozen=True)
class Found:
    """A package's launch files as (path, shown), and the installed launch folder."""

    files: tuple[tuple[Path, str], ...]
    installed: Path | None  # <prefix>/share/<pkg>/launch, when the package is installed
    from_source: bool


def package_launch_files(package: str, workspace: Workspace) -> Found:
    """The launch files of `package`: the source folder's, shown relative to the
    package (``launch/x.py``), else the installed ones (``share/<pkg>/launch/x.py``)."""
    owner = workspace.owner(package)
    installed = owner / "share" / package / "launch" if owner is not None else None
    source = find_package(workspace.root, package) if workspace.root is not None else None
    if source is not None and (source / "launch").is_dir():
        return Found(_listed(source / "launch", "launch"), installed, True)
    if installed is not None and installed.is_dir():
        return Found(_listed(installed, f"share/{package}/launch"), installed, False)
    return Found((), installed, False)


def _listed(folder: Path, shown: str) -> tuple[tuple[Path, str], ...]:
    try:
        names = sorted(p.name for p in folder.iterdir() if p.is_file() and is_launch_name(p.name))
    except OSError:
        return ()
    return tuple((folder / name, f"{shown}/{name}") for name in names[:MAX_FILES])


def install_note(path: Path, shown: str, package: str, installed: Path | None) -> str | None:
    """What `ros2 launch` would run instead of the source file `path`: nothing (it is
    not installed) or an older copy; None when the copy is this file."""
    if installed is None or not installed.parent.is_dir():
        return None  # the package is not built at all: the build check says so
    copy = installed / path.name
    if not copy.is_file():
        return (
            f"{shown} is not installed (the build's share/{package}/launch has no {path.name}): "
            f"`ros2 launch {package} {path.name}` does not find it; install it (data_files "
            "in setup.py) and rebuild"
        )
    try:
        same = copy.samefile(path) or copy.read_bytes() == path.read_bytes()
    except OSError:
        return None
    if same:
        return None
    return (
        f"{shown} differs from its installed copy, which is what `ros2 launch` runs: "
        "rebuild (colcon build) to install it"
    )
