"""What a launch file says, as read without running it (pure records)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path


@dataclass(frozen=True)
class ParamSetting:
    """One parameter a launch file sets on a node (dotted when nested)."""

    name: str
    line: int


@dataclass(frozen=True)
class Unread:
    """Something the file decides only when it runs (a substitution, a call, a file of
    parameters): said, never guessed."""

    line: int
    what: str


@dataclass(frozen=True)
class NodeEntry:
    """A node the file starts; None where the file gives no plain text."""

    line: int
    package: str | None
    executable: str | None
    name: str | None = None
    params: tuple[ParamSetting, ...] = ()


@dataclass(frozen=True)
class LaunchFile:
    """One launch file: its nodes, the launch arguments it declares, what was not read;
    `shown` is its path as the user knows it, never the checking machine's absolute path."""

    path: Path
    shown: str
    nodes: tuple[NodeEntry, ...] = ()
    arguments: tuple[str, ...] = ()
    unread: tuple[Unread, ...] = field(default=())

    def at(self, line: int) -> str:
        """'launch/x.py line 40', where a note points."""
        return f"{self.shown} line {line}"
