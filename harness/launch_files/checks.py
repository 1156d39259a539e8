"""The advice a launch file gets, each note naming the file and line (pure): a node the
build cannot start (package not installed, executable not in ``lib/<pkg>/``), or a
parameter the node does not declare, whose override is dropped without a word (the
closest declared names offered, two at most: letters cannot tell 'info' from 'status')."""

from __future__ import annotations

import difflib
from collections.abc import Sequence

from harness.launch_files.entries import LaunchFile, NodeEntry
from harness.launch_files.finding import Workspace

__all__ = ["build_problem", "declared_list", "undeclared_parameters", "unread_notes"]

# Every Jazzy node declares these; no launch file is expected to set them.
BUILT_IN = ("use_sim_time",)
NOT_SHOWN = ("start_type_description_service",)
CLOSE_ENOUGH = 0.6  # difflib ratio for "did you mean"


def build_problem(
    file: LaunchFile, entry: NodeEntry, workspace: Workspace, where: str
) -> str | None:
    """Why the build cannot start `entry` (its package or executable is missing), or None.
    `where` names the place packages were looked for ("the workspace")."""
    if entry.package is None or entry.executable is None:
        return None  # not plain text: the unread notes say so
    owner = workspace.owner(entry.package)
    if owner is None:
        return (
            f"{file.at(entry.line)}: starts package {entry.package!r}, which is not in "
            f"{where}: `ros2 launch` cannot start that node"
        )
    folder = owner / "lib" / entry.package
    if (folder / entry.executable).is_file():
        return None
    try:
        there = sorted(p.name for p in folder.iterdir() if p.is_file())
    except OSError:
        there = []
    return (
        f"{file.at(entry.line)}: starts executable {entry.executable!r} of {entry.package}, "
        f"which its build does not install (lib/{entry.package} has: "
        f"{', '.join(there) or 'nothing'}): `ros2 launch` cannot start that node"
    )


def declared_list(declared: Sequence[str]) -> str:
    """The node's own parameters in order, then the built-in ones it has."""
    hidden = (*BUILT_IN, *NOT_SHOWN)
    own = sorted(d for d in declared if d not in hidden and not d.startswith("qos_overrides."))
    return ", ".join([*own, *(b for b in BUILT_IN if b in declared)]) or "nothing"


def closest(name: str, candidates: Sequence[str]) -> list[str]:
    """The two candidates most like `name` that are close enough, closest first."""
    return difflib.get_close_matches(name, candidates, n=2, cutoff=CLOSE_ENOUGH)


def undeclared_parameters(
    file: LaunchFile, entry: NodeEntry, node: str, declared: Sequence[str]
) -> list[str]:
    """A note for each parameter `entry` sets that `node` does not declare."""
    known = set(declared)
    set_here = {p.name for p in entry.params}
    unset = [d for d in declared if d not in set_here and d not in NOT_SHOWN]
    notes = []
    for setting in entry.params:
        if setting.name in known:
            continue
        guesses = " or ".join(repr(g) for g in closest(setting.name, unset))
        mean = f"did you mean {guesses}? " if guesses else ""
        notes.append(
            f"{file.at(setting.line)}: sets parameter {setting.name!r}, which {node} does not "
            f"declare ({mean}it declares {declared_list(declared)}): the node never sees it"
        )
    return notes


def unread_notes(file: LaunchFile) -> list[str]:
    """What could not be read without running the file, each at its line."""
    return [f"{file.at(u.line)}: {u.what}" for u in file.unread]
