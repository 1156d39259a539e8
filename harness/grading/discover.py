"""Which folders are students, and what each one handed in (pure: files only).

The rules (one student or a folder of them; package, workspace or script; which
script is the node; what is passed over, and when nothing handed in is a usage
error) are docs/grading.md's "What counts as a student".
"""

from __future__ import annotations

import ast
import os
import re
from collections import Counter
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from harness.errors import ConfigError

__all__ = [
    "ARCHIVE_SUFFIXES",
    "GRADES_MARKER",
    "Discovery",
    "Entry",
    "Student",
    "add_folder",
    "archive_stem",
    "discover",
    "is_archive",
    "named",
    "passed_over",
    "student_in",
]

GRADES_MARKER = ".fossbot-hil-grades"  # marks an output folder of `grade`
MANIFEST = "package.xml"
NEVER_SEARCHED = {"build", "install", "log", "__pycache__", "node_modules"}
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE")
MAX_DEPTH = 4  # src/<repo>/<group>/<package>/package.xml
NOT_A_NODE = {"setup.py", "conftest.py", "__init__.py"}
LAB_NODE = "fossbot_lidar_node.py"  # what Lab 07 names the node: the node, beside any helper
# What a __main__ guard calls (itself or through the script's functions) that starts a
# node: rclpy's init, any spin (an executor's too), or a Node made.
STARTS_A_NODE = {
    "rclpy.init",
    "rclpy.create_node",
    ".spin",
    ".spin_once",
    ".spin_until_future_complete",
}
RCLPY_STARTS = {"init", "create_node", "spin", "spin_once", "spin_until_future_complete"}
SCRIPT_PEEK_BYTES = 1 << 20
# What LMSs export; the longest suffix first (".tar.gz" before ".tar").
ARCHIVE_SUFFIXES = (".tar.gz", ".tgz", ".tar.bz2", ".tbz2", ".tar.xz", ".txz", ".tar", ".zip")
OS_LITTER = {"__MACOSX", "Thumbs.db", "desktop.ini"}  # file managers' own files, never handed in
NOT_A_SUBMISSION = "not a submission: a file, not a folder or archive"


@dataclass(frozen=True)
class Student:
    """One student's hand-in: how to build it (base paths) or run it (script)."""

    name: str
    folder: Path
    kind: str  # "workspace", "package", "script" or "none"
    base_paths: tuple[Path, ...] = ()  # package folders, for colcon --base-paths
    script: Path | None = None
    problem: str | None = None  # why there is nothing to build or run
    slug: str = ""  # a file-name-safe, unique form of `name` for the artifact folder


def absolute(student: Student) -> Student:
    """`student` with every path absolute (no link followed): a cluster worker runs in a
    folder of its own, where the paths given on the command line mean nothing."""

    def made(path: Path) -> Path:
        return Path(os.path.abspath(path))

    return replace(
        student,
        folder=made(student.folder),
        base_paths=tuple(made(p) for p in student.base_paths),
        script=None if student.script is None else made(student.script),
    )


@dataclass(frozen=True)
class Entry:
    """A hand-in found, before it is named (`named` names them all together)."""

    where: str  # the DIR (or class archive) it was found in: tells two equal names apart
    name: str  # its own name: the folder's or file's, an archive's without .zip, .tar.gz...
    path: Path  # the folder to look at; with a `problem`, what was handed in
    problem: str | None = None  # why there is nothing to look at (a loose file, a bad archive)
    file: str = ""  # the archive's file name, for two hand-ins of one name in one DIR
    note: str = ""  # added to the reason when the folder holds no node (links left out)

    def student(self, name: str, slug: str) -> Student:
        if self.problem is not None:
            return Student(name, self.path, "none", problem=self.problem, slug=slug)
        student = student_in(self.path, name)
        if student.problem is not None and self.note:
            return replace(student, problem=f"{student.problem}; {self.note}", slug=slug)
        return replace(student, slug=slug)


@dataclass
class Discovery:
    """The students found, the archives still to unpack, and what was passed over (with why);
    archives.unpack_submissions names `students` again together with the archives' ones."""

    students: list[Student] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    entries: list[Entry] = field(default_factory=list)  # folders and loose files
    archives: list[Entry] = field(default_factory=list)  # one student each, in a DIR
    class_archives: list[Entry] = field(default_factory=list)  # given as a DIR


def archive_suffix(name: str) -> str | None:
    """The archive suffix `name` ends with (any case), or None."""
    folded = name.casefold()
    return next((s for s in ARCHIVE_SUFFIXES if folded.endswith(s) and len(name) > len(s)), None)


def is_archive(path: Path) -> bool:
    """An archive by its name: .zip, .tar, .tar.gz, .tgz, .tar.bz2, .tbz2, .tar.xz, .txz."""
    return archive_suffix(path.name) is not None


def archive_stem(name: str) -> str:
    """`name` without its archive suffix: alex.tar.gz -> alex."""
    suffix = archive_suffix(name)
    return name[: len(name) - len(suffix)] if suffix else name


def passed_over(name: str) -> bool:
    """Hidden entries and file managers' litter: never a submission, never a row."""
    return name.startswith(".") or name in OS_LITTER


def _searchable(folder: Path) -> bool:
    name = folder.name
    return not (
        name.startswith(".")
        or name in NEVER_SEARCHED
        or any((folder / marker).exists() for marker in IGNORE_MARKERS)
    )


def _subfolders(folder: Path) -> list[Path]:
    try:
        entries = sorted(folder.iterdir(), key=lambda p: p.name)
    except OSError:
        return []
    return [p for p in entries if p.is_dir() and not p.is_symlink()]


def package_folders(root: Path, depth: int = MAX_DEPTH) -> list[Path]:
    """Folders below `root` with a package.xml, not descending into a package (as colcon)."""
    if (root / MANIFEST).is_file():
        return [root]
    if depth == 0:
        return []
    found: list[Path] = []
    for sub in _subfolders(root):
        if _searchable(sub):
            found += package_folders(sub, depth - 1)
    return found


def _read_script(script: Path) -> str:
    try:
        with open(script, "rb") as handle:
            return handle.read(SCRIPT_PEEK_BYTES).decode("utf-8", "replace")
    except OSError:
        return ""


def _imports_rclpy(script: Path) -> bool:
    text = _read_script(script)
    return re.search(r"^\s*(import|from)\s+rclpy\b", text, re.MULTILINE) is not None


def node_scripts(folder: Path) -> list[Path]:
    """Top-level .py files that could be the node (not setup.py, tests or launch files)."""
    try:
        files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix == ".py")
    except OSError:
        return []
    return [
        p
        for p in files
        if p.name not in NOT_A_NODE
        and not p.name.startswith("test_")
        and not p.name.endswith("_launch.py")
    ]


def _called_names(nodes: Iterable[ast.AST]) -> set[str]:
    """What `nodes` call: ``f()`` gives f; ``rclpy.init()`` gives .init and rclpy.init;
    ``a.b.Node()`` gives .Node."""
    names: set[str] = set()
    for node in nodes:
        for sub in ast.walk(node):
            if isinstance(sub, ast.Call):
                if isinstance(sub.func, ast.Name):
                    names.add(sub.func.id)
                elif isinstance(sub.func, ast.Attribute):
                    names.add("." + sub.func.attr)
                    if isinstance(sub.func.value, ast.Name):
                        names.add(f"{sub.func.value.id}.{sub.func.attr}")
    return names


def _base_names(cls: ast.ClassDef) -> set[str]:
    """The names of the classes `cls` derives from (``rclpy.node.Node`` gives Node)."""
    return {
        b.id if isinstance(b, ast.Name) else b.attr
        for b in cls.bases
        if isinstance(b, (ast.Name, ast.Attribute))
    }


def _rclpy_starts(tree: ast.Module) -> set[str]:
    """The names a script calls rclpy's init or spins by (``from rclpy import init, spin``)."""
    return {
        alias.asname or alias.name
        for s in ast.walk(tree)
        if isinstance(s, ast.ImportFrom) and s.module == "rclpy"
        for alias in s.names
        if alias.name in RCLPY_STARTS
    }


def _is_main_guard(statement: ast.stmt) -> bool:
    """``if __name__ == "__main__":`` (either way round)."""
    if not isinstance(statement, ast.If) or not isinstance(statement.test, ast.Compare):
        return False
    test = statement.test
    sides = [test.left, *test.comparators]
    return (
        len(sides) == 2
        and isinstance(test.ops[0], ast.Eq)
        and any(isinstance(s, ast.Name) and s.id == "__name__" for s in sides)
        and any(isinstance(s, ast.Constant) and s.value == "__main__" for s in sides)
    )


def _starts_a_node(script: Path) -> bool:
    """Whether `script` has a ``__main__`` guard that starts a ROS node: what it calls
    (through the script's own functions and classes) includes rclpy's init or a spin, or
    makes a Node (a class of the script deriving from Node counts as one). A helper
    module's guard, if it has one, tries out its functions instead."""
    try:
        tree = ast.parse(_read_script(script))
    except (SyntaxError, ValueError, RecursionError):
        return False
    guards = [s for s in tree.body if _is_main_guard(s)]
    if not guards:
        return False
    defined: dict[str, ast.stmt] = {}
    for statement in tree.body:
        if isinstance(statement, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            defined[statement.name] = statement
    nodes = {"Node"}  # and the script's classes deriving from one
    classes = [s for s in defined.values() if isinstance(s, ast.ClassDef)]
    while more_nodes := {c.name for c in classes if _base_names(c) & nodes} - nodes:
        nodes |= more_nodes
    starts = STARTS_A_NODE | nodes | {"." + n for n in nodes} | _rclpy_starts(tree)
    seen: set[str] = set()
    calls = _called_names(guards)
    while True:
        if calls & starts:
            return True
        more = {n for n in calls & defined.keys() if n not in seen}
        if not more:
            return False
        seen |= more
        calls = _called_names(defined[n] for n in more)


def node_script(scripts: Sequence[Path]) -> list[Path]:
    """Which of a hand-in's top-level scripts is its node (one), or the candidates left.

    A student may split the node in two (the node and a module of helpers, both
    importing rclpy). The lab names its node fossbot_lidar_node.py: that file is the
    node. Otherwise the one whose ``__main__`` guard starts a node, else the one that
    imports rclpy; a tie leaves the candidates it could not tell apart.
    """
    if len(scripts) <= 1:
        return list(scripts)
    named = [p for p in scripts if p.name == LAB_NODE]
    if named:
        return named
    for choose in (_starts_a_node, _imports_rclpy):
        chosen = [p for p in scripts if choose(p)]
        if len(chosen) == 1:
            return chosen
        if chosen:
            scripts = chosen
    return list(scripts)


def student_in(folder: Path, name: str | None = None) -> Student:
    """What `folder` holds, as a student named `name` (default: the folder's name)."""
    name = name or folder.name
    if (folder / MANIFEST).is_file():
        return Student(name, folder, "package", base_paths=(folder,))
    src = folder / "src"
    packages = package_folders(src, MAX_DEPTH - 1) if src.is_dir() else []
    if not packages:
        packages = [
            p
            for sub in _subfolders(folder)
            if _searchable(sub)
            for p in package_folders(sub, MAX_DEPTH - 1)
        ]
    if packages:
        return Student(name, folder, "workspace", base_paths=tuple(packages))
    scripts = node_script(node_scripts(folder))
    if len(scripts) == 1:
        return Student(name, folder, "script", script=scripts[0])
    if scripts:
        listed = ", ".join(p.name for p in scripts)
        problem = (
            f"cannot tell which .py file is the node ({listed}): name the node {LAB_NODE}, "
            "or hand in a package"
        )
    else:
        problem = "no node found: no package.xml and no .py file"
    return Student(name, folder, "none", problem=problem)


def _is_single_student(folder: Path) -> bool:
    """A folder that is one hand-in itself, not a folder of hand-ins."""
    student = student_in(folder)
    if student.kind == "package" or (student.kind == "workspace" and (folder / "src").is_dir()):
        return True
    has_subfolders = any(_searchable(p) for p in _subfolders(folder))
    return student.kind == "script" and not has_subfolders


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except ValueError:
        return False
    return True


def slugify(name: str) -> str:
    """A folder name for `name`: letters, digits, '.', '_' and '-' kept, the rest '_'."""
    slug = "".join(c if c.isalnum() or c in "._-" else "_" for c in name).lstrip(".")
    return slug or "student"


def named(found: Iterable[Entry]) -> list[Student]:
    """The students, sorted by name; a name given twice (in two DIRs) gets its DIR's name.

    Two of one name in one DIR (alex/ and alex.zip) are told apart by the
    archive's file name; names that are still equal get " (2)". Slugs are
    unique regardless of case.
    """
    entries = list(found)
    names = [e.name for e in entries]
    for form in (lambda e: f"{e.where}/{e.name}", lambda e: f"{e.where}/{e.file or e.name}"):
        counts = Counter(names)
        names = [form(e) if counts[n] > 1 else n for e, n in zip(entries, names, strict=True)]
    students: list[Student] = []
    taken: set[str] = set()
    slugs: set[str] = set()
    for entry, base in zip(entries, names, strict=True):
        name, n = base, 2
        while name in taken:
            name, n = f"{base} ({n})", n + 1
        taken.add(name)
        slug = base_slug = slugify(name)
        n = 2
        while slug.casefold() in slugs:
            slug, n = f"{base_slug}-{n}", n + 1
        slugs.add(slug.casefold())
        students.append(entry.student(name, slug))
    return sorted(students, key=lambda s: (s.name.casefold(), s.name))


def add_folder(
    result: Discovery,
    folder: Path,
    *,
    name: str,
    where: str,
    file: str = "",
    exclude: Path | None = None,
) -> None:
    """A folder given to grade (or a class archive unpacked), into `result`: one student
    (`name`, found in `where`) when it is one hand-in; otherwise a subfolder is a student,
    an archive a student to unpack, another file a row saying why it is not graded."""
    if _is_single_student(folder):
        result.entries.append(Entry(where, name, folder, file=file))
        return
    for entry in sorted(folder.iterdir(), key=lambda p: p.name):
        if passed_over(entry.name) or (exclude is not None and _inside(entry, exclude)):
            continue
        if entry.is_dir():
            if (entry / GRADES_MARKER).exists():
                result.skipped.append(f"{entry}: an output folder of `fossbot-hil grade`")
            else:
                result.entries.append(Entry(name, entry.name, entry))
        elif is_archive(entry) and entry.is_file():
            stem = archive_stem(entry.name)
            result.archives.append(Entry(name, stem, entry, file=entry.name))
        else:
            result.entries.append(Entry(name, entry.name, entry, problem=NOT_A_SUBMISSION))


def _once(entries: list[Entry]) -> list[Entry]:
    """The entries without a path given twice."""
    seen: set[Path] = set()
    unique = []
    for entry in entries:
        key = entry.path.resolve()
        if key not in seen:
            seen.add(key)
            unique.append(entry)
    return unique


def discover(dirs: Sequence[str | Path], *, exclude: str | Path | None = None) -> Discovery:
    """The students in `dirs`; ConfigError (exit 2) for a missing folder, or for DIRs that
    hold nothing handed in (no folder, no archive).

    `exclude` is the grader's output folder: never a student, even inside a DIR.
    Archives are only noted here (`archives`, `class_archives`), not opened:
    archives.unpack_submissions unpacks them into the output folder.
    """
    result = Discovery()
    for given in dirs:
        path = Path(given)
        if not path.exists():
            raise ConfigError(f"{given}: no such {'archive' if is_archive(path) else 'folder'}")
        absolute = Path(os.path.abspath(path))  # "." named after the folder, no link followed
        where = absolute.parent.name
        if path.is_file() and is_archive(path):
            stem = archive_stem(path.name)
            result.class_archives.append(Entry(where, stem, path, file=path.name))
        elif path.is_dir():
            add_folder(
                result,
                path,
                name=absolute.name,
                where=where,
                exclude=None if exclude is None else Path(exclude),
            )
        else:
            raise ConfigError(
                f"{given}: not a folder or archive (give a folder of student folders, "
                "or an archive of them)"
            )
    result.entries = _once(result.entries)
    result.archives = _once(result.archives)
    result.class_archives = _once(result.class_archives)
    result.students = named(result.entries)
    some_archive = result.archives or result.class_archives
    if not some_archive and all(e.problem is not None for e in result.entries):
        # No folder and no archive (an empty DIR, only loose files): likely the wrong DIR.
        # Folders whose hand-ins cannot run are a class all the same: a row each says why.
        listed = ", ".join(str(d) for d in dirs)
        raise ConfigError(
            f"no students found in {listed}: expected one folder (or archive) per student "
            "holding a colcon workspace (src/), a package (package.xml) or a node script (.py)"
        )
    return result
