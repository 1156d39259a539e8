"""Which files make up the node under test, and whether a change to them needs a build (pure).

Only what the command line tells: a script and the .py files beside it (not
the folders below: a script in a home folder must not watch all of it), a
program that is a file, a workspace package's sources (rebuilt with the
workspace's own colcon flags unless ``--symlink-install`` runs them where
they are), a processor file, scenario files given by path. The bundled
node is not the user's to edit: nothing to watch.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from harness.errors import OptionError
from harness.nodes.command import python_script_of, split_command
from harness.nodes.package_folder import WORKSPACE_OUTPUTS, find_package
from harness.nodes.setup_problems import is_python
from harness.option_names import escaped

if TYPE_CHECKING:
    from harness.links.base import LinkOptions

__all__ = ["Build", "NodeSources", "Watched", "node_sources", "scenario_sources"]

BUILD_FILES = frozenset({"setup.py", "setup.cfg", "package.xml"})
RESOURCE_FOLDER = "resource"
SKIPPED_FOLDERS = frozenset({"__pycache__", *WORKSPACE_OUTPUTS})
AMENT_MARKERS = Path("share/ament_index/resource_index/packages")


def _hidden(name: str) -> bool:
    """An editor's or a tool's own file (.#node.py, .node.py.swp, .git, .ruff_cache)."""
    return name.startswith((".", "~"))


@dataclass(frozen=True)
class Watched:
    """A folder to watch and which of its files count: those directly in it named in
    `names` or with one of `suffixes`, or, `recursive`, a package's (`package_file`)."""

    folder: Path
    recursive: bool = False
    names: frozenset[str] = frozenset()
    suffixes: tuple[str, ...] = ()

    def matches(self, path: Path) -> bool:
        """Does a change to `path` concern the node (or the scenarios)?"""
        try:
            relative = path.relative_to(self.folder)
        except ValueError:
            return False
        parts = relative.parts
        if not parts or any(_hidden(p) for p in parts):
            return False
        if self.recursive:
            return package_file(relative)
        if len(parts) != 1:
            return False
        return parts[0] in self.names or (bool(self.suffixes) and path.suffix in self.suffixes)


def package_file(relative: Path) -> bool:
    """A file of a package's sources that the node's run depends on: a Python file, the
    package's setup.py, setup.cfg or package.xml, or anything in its resource/ folder."""
    parts = relative.parts
    if any(p in SKIPPED_FOLDERS or p.endswith(".egg-info") for p in parts[:-1]):
        return False
    if len(parts) == 1 and parts[0] in BUILD_FILES:
        return True
    if parts[0] == RESOURCE_FOLDER and len(parts) > 1:
        return True
    return relative.suffix == ".py"


def needs_build_files(relative: Path) -> bool:
    """A change colcon must install even into a --symlink-install workspace."""
    parts = relative.parts
    return (len(parts) == 1 and parts[0] in BUILD_FILES) or parts[0] == RESOURCE_FOLDER


@dataclass(frozen=True)
class Build:
    """How to rebuild the package under test, in the workspace's own install layout."""

    workspace: Path
    package: str
    source: Path  # the package's folder (its package.xml)
    symlink_install: bool = False
    merge_install: bool = False

    def command(self, colcon: str, extra: Sequence[str] = ()) -> list[str]:
        """The colcon command line, run in `workspace`; `extra` goes after ``build``."""
        argv = [colcon, "build", *extra, "--packages-select", self.package]
        if self.symlink_install:
            argv.append("--symlink-install")
        if self.merge_install:
            argv.append("--merge-install")
        return argv

    def needed(self, changed: Iterable[Path]) -> bool:
        """Must these changed files be built before the node runs them?"""
        for path in changed:
            try:
                relative = path.relative_to(self.source)
            except ValueError:
                continue
            if not package_file(relative):
                continue
            if not self.symlink_install or needs_build_files(relative):
                return True
        return False


@dataclass(frozen=True)
class NodeSources:
    """What to watch for a run, in words for the screen, and the build a change may need."""

    watched: tuple[Watched, ...] = ()
    description: tuple[str, ...] = ()
    build: Build | None = None
    scenario_files: frozenset[Path] = field(default_factory=frozenset)

    def matches(self, path: str | Path) -> bool:
        """Does a change to `path` concern this run?"""
        resolved = Path(path)
        return any(w.matches(resolved) for w in self.watched)

    def plus(self, other: NodeSources) -> NodeSources:
        """Both sets of sources (the node's and the scenarios'), one build at most."""
        return NodeSources(
            self.watched + other.watched,
            self.description + other.description,
            self.build or other.build,
            self.scenario_files | other.scenario_files,
        )


def _real(path: str | Path) -> Path:
    """An absolute path with symlinks resolved (the watcher reports real paths)."""
    return Path(os.path.realpath(os.path.expanduser(path)))


def _script_sources(script: Path, shown: str) -> NodeSources:
    folder = script.parent
    return NodeSources(
        (Watched(folder, suffixes=(".py",)),), (f"{shown} and the .py files beside it in {folder}",)
    )


def _file_sources(program: Path, shown: str) -> NodeSources:
    return NodeSources((Watched(program.parent, names=frozenset({program.name})),), (shown,))


def command_sources(command: str) -> NodeSources:
    """The files a node command line runs: a script and the .py files beside it, or
    its program when that is a file; OptionError when the command names none."""
    argv = split_command(command)
    program = argv[0]
    given = "{node} " + escaped(repr(command))  # --node 'python3 x.py', when worded
    script = python_script_of(argv) if is_python(program) else None
    if script is None and is_python(program):  # -m or -c: no file on the command line
        raise OptionError(
            "watch",
            f"{{watch}}: cannot tell which files {given} runs; "
            "give the script's path, e.g. {node} 'python3 path/to/node.py'",
        )
    if script is None and program.endswith(".py"):
        script = program
    if script is not None:
        path = Path(os.path.expanduser(script))
        if not path.is_file():
            raise OptionError("watch", f"{{watch}}: {given}: no such script {escaped(script)}")
        return _script_sources(_real(path), path.name)
    if "/" in program and Path(os.path.expanduser(program)).is_file():
        return _file_sources(_real(program), program)
    raise OptionError(
        "watch",
        f"{{watch}}: cannot tell which files {given} runs ({escaped(repr(program))} is a "
        "program, not a file of yours); give the script's path, or use "
        "{workspace}/{package}/{executable}",
    )


def symlink_installed(workspace: Path, package: str) -> bool:
    """Was `package` built with ``colcon build --symlink-install``? Then its install
    has an .egg-link to the sources, and build/P links to the source folders."""
    install = workspace / "install"
    for prefix in (install / package, install):
        if any(prefix.glob("lib/python3*/site-packages/*.egg-link")):
            return True
    build = workspace / "build" / package
    try:
        return any(p.is_symlink() and p.is_dir() for p in build.iterdir())
    except OSError:
        return False


def merge_installed(workspace: Path) -> bool:
    """Was the workspace built with ``--merge-install`` (one prefix for every package)?"""
    return (workspace / "install" / AMENT_MARKERS).is_dir()


def package_sources(workspace: str, package: str) -> NodeSources:
    """The package's source folder in `workspace` and how to rebuild it."""
    root = Path(os.path.expanduser(workspace))
    if not (root / "install").is_dir():
        raise OptionError(
            "watch",
            f"{{watch}}: {{workspace}} {escaped(workspace)} has no install/ folder: give the "
            "colcon workspace itself (the folder you run colcon build in), built once",
        )
    source = find_package(root, package)
    if source is None:
        raise OptionError(
            "watch",
            f"{{watch}}: no package.xml naming {escaped(package)} under {{workspace}} "
            f"{escaped(workspace)} (outside its build/, install/ and log/): its sources are "
            "what {watch} watches",
        )
    symlinked = symlink_installed(root, package)
    build = Build(_real(root), package, _real(source), symlinked, merge_installed(root))
    how = "--symlink-install: a .py change needs no build" if symlinked else "rebuilt on change"
    return NodeSources(
        (Watched(build.source, recursive=True),),
        (f"package {package} in {build.source} ({how})",),
        build,
    )


def processor_sources(processor: str | None) -> NodeSources:
    """`--processor FILE.py:FUNCTION`: the file; a module name brings nothing to watch
    (Python keeps an imported module: a change would not be run)."""
    target = (processor or "").rpartition(":")[0]
    if not target.endswith(".py"):
        return NodeSources()
    path = Path(os.path.expanduser(target))
    if not path.is_file():
        raise OptionError.saying("processor", f"{processor!r}: no such file {target}")
    return _file_sources(_real(path), target)


def node_sources(link: str, options: LinkOptions) -> NodeSources:
    """The files of the node (or processing function) `options` name; none for the bundled."""
    from harness.links.kinds import link_kind

    if not link_kind(link).runs_node:
        return processor_sources(options.processor)
    if options.node:
        return command_sources(options.node)
    if options.package:
        if options.workspace is None:
            raise OptionError(
                "watch",
                "{watch} with {package} needs {workspace} DIR: the colcon workspace whose "
                "sources to watch and rebuild",
            )
        return package_sources(options.workspace, options.package)
    return NodeSources()


def scenario_sources(refs: Iterable[str]) -> NodeSources:
    """The scenario files given by path (shipped names are not the user's to edit)."""
    files = [_real(r) for r in refs if Path(os.path.expanduser(r)).is_file()]
    watched = tuple(Watched(f.parent, names=frozenset({f.name})) for f in files)
    shown = tuple(f"scenario file {f}" for f in files)
    return NodeSources(watched, shown, None, frozenset(files))
