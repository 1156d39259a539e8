"""One run's launch-file check: files read once at the start, the running node asked once.

The ros2 link's ``run_session`` holds it; every scenario gets the same notes, which
reports print once. A launch file is advice: nothing here fails a scenario."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from harness.launch_files.checks import build_problem, undeclared_parameters, unread_notes
from harness.launch_files.entries import LaunchFile, NodeEntry
from harness.launch_files.finding import install_note, package_launch_files, workspace_of
from harness.launch_files.reading import read_launch_file
from harness.option_names import named

__all__ = ["Asked", "LaunchCheck"]

# What asking the running node gave: (its name, the parameters it declares), or why
# it could not be asked (harness.ros.parameters).
Asked = tuple[str, list[str]] | str


@dataclass
class LaunchCheck:
    """The launch files of the run's package and what they get wrong; `executable` names the
    node the run starts (None with a launch file: its entries are the node's)."""

    package: str
    executable: str | None
    files: tuple[LaunchFile, ...]
    static: tuple[str, ...]  # notes that need no running node
    checked: tuple[str, ...] | None = None  # notes from the running node, once asked

    @classmethod
    def for_run(
        cls,
        package: str,
        executable: str | None,
        workspace: str | None,
        *,
        launched: str | None = None,
        passed: Sequence[str] = (),
    ) -> LaunchCheck | None:
        """The package's launch files, or the one `run --launch` starts (`launched`), whose
        arguments must take the `passed` parameters; None when there is nothing to check."""
        space = workspace_of(workspace)
        where = "the workspace" if workspace is not None else "AMENT_PREFIX_PATH"
        found = package_launch_files(package, space)
        files: list[LaunchFile] = []
        static: list[str] = []
        for path, shown in found.files:
            read = read_launch_file(path, shown) if launched in (None, path.name) else None
            if read is None:
                continue
            files.append(read)
            note = found.from_source and install_note(path, shown, package, found.installed)
            static += [note] if note else []
            static += [
                f"{named('launch')}: {shown} declares no launch argument {name!r}, so the harness "
                f"cannot pass {name} to the node through it (the node keeps the file's value)"
                for name in dict.fromkeys(passed if launched else ())
                if name not in read.arguments
            ]
        for file in files:
            static += unread_notes(file)
            for entry in file.nodes:
                problem = build_problem(file, entry, space, where)
                static += [problem] if problem else []
        if not files and not static:
            return None
        return cls(package, None if launched else executable, tuple(files), tuple(static))

    @property
    def sets_parameters(self) -> bool:
        """Does any node entry set a parameter (else the node need not be asked)?"""
        return any(entry.params for file in self.files for entry in file.nodes)

    def notes(self, ask: Callable[[], Asked] | None) -> list[str]:
        """The run's notes; `ask` (None while the node cannot be asked: not up, or
        gone) is called once in a run, the first time it is given."""
        if self.checked is None and ask is not None and self.sets_parameters:
            self.checked = tuple(self._against(ask()))
        return [*self.static, *(self.checked or ())]

    def _against(self, asked: Asked) -> list[str]:
        if isinstance(asked, str):
            shown = ", ".join(f.shown for f in self.files if any(e.params for e in f.nodes))
            return [f"{shown}: parameters not checked against the node: {asked}"]
        node, declared = asked
        return [
            note
            for file, entry in self._entries_for(node)
            for note in undeclared_parameters(file, entry, node, declared)
        ]

    def _entries_for(self, node: str) -> list[tuple[LaunchFile, NodeEntry]]:
        """The entries that start the node under test: its package and executable; with
        --launch, the entry named as the node is, or the file's only one."""
        pairs = [(file, entry) for file in self.files for entry in file.nodes]
        if self.executable is not None:
            wanted = (self.package, self.executable)
            return [(f, entry) for f, entry in pairs if (entry.package, entry.executable) == wanted]
        named = [(file, entry) for file, entry in pairs if entry.name == node.rsplit("/", 1)[-1]]
        return named or (pairs if len(pairs) == 1 else [])
