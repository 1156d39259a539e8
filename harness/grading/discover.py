"""Which folders are students, and what each one handed in (pure: files only).

The rules, also in docs/grading.md:

- A folder given on the command line is **one student** when it is itself a
  colcon workspace or package, or when it has no subfolders and holds one
  node script. Otherwise **each subfolder is a student** (hidden folders and
  the grader's own output folder are skipped; loose files are listed as
  skipped).
- A student folder is a **package** when it has a package.xml at its top; a
  **workspace** when package.xml files sit below it (only under src/ if it
  has one; build/, install/, log/, hidden folders and folders holding a
  COLCON_IGNORE are never searched, at most four levels deep); a **script**
  when it has no package.xml and one top-level .py file, or several of which
  exactly one imports rclpy. Anything else is still a student, with the
  reason there is nothing to run.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from harness.errors import ConfigError

__all__ = ["GRADES_MARKER", "Discovery", "Student", "discover", "student_in"]

GRADES_MARKER = ".fossbot-hil-grades"  # marks an output folder of `grade`
MANIFEST = "package.xml"
NEVER_SEARCHED = {"build", "install", "log", "__pycache__", "node_modules"}
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE")
MAX_DEPTH = 4  # src/<repo>/<group>/<package>/package.xml
NOT_A_NODE = {"setup.py", "conftest.py", "__init__.py"}
SCRIPT_PEEK_BYTES = 1 << 20


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


@dataclass
class Discovery:
    """The students found, and the entries that were passed over (with why)."""

    students: list[Student] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)


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


def _imports_rclpy(script: Path) -> bool:
    try:
        with open(script, "rb") as handle:
            text = handle.read(SCRIPT_PEEK_BYTES).decode("utf-8", "replace")
    except OSError:
        return False
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
    scripts = node_scripts(folder)
    if len(scripts) > 1:
        scripts = [p for p in scripts if _imports_rclpy(p)] or scripts
    if len(scripts) == 1:
        return Student(name, folder, "script", script=scripts[0])
    if scripts:
        listed = ", ".join(p.name for p in scripts)
        problem = f"cannot tell which .py file is the node ({listed}): hand in one, or a package"
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


def _named(found: Iterable[tuple[Path, Path]]) -> list[Student]:
    """Students named by folder; a name given twice (in two DIRs) gets its DIR's name."""
    pairs = list(found)
    counts: dict[str, int] = {}
    for _, folder in pairs:
        counts[folder.name] = counts.get(folder.name, 0) + 1
    students: list[Student] = []
    slugs: set[str] = set()
    for parent, folder in pairs:
        name = folder.name if counts[folder.name] == 1 else f"{parent.name}/{folder.name}"
        slug = base = slugify(name)
        n = 2
        while slug.casefold() in slugs:
            slug, n = f"{base}-{n}", n + 1
        slugs.add(slug.casefold())
        student = student_in(folder, name)
        students.append(
            Student(
                student.name,
                student.folder,
                student.kind,
                student.base_paths,
                student.script,
                student.problem,
                slug,
            )
        )
    return sorted(students, key=lambda s: (s.name.casefold(), s.name))


def discover(dirs: Sequence[str | Path], *, exclude: str | Path | None = None) -> Discovery:
    """The students in `dirs`; ConfigError (exit 2) for a missing folder or no student at all.

    `exclude` is the grader's output folder: never a student, even inside a DIR.
    """
    result = Discovery()
    found: list[tuple[Path, Path]] = []
    for given in dirs:
        folder = Path(given)
        if not folder.exists():
            raise ConfigError(f"{given}: no such folder")
        if not folder.is_dir():
            raise ConfigError(f"{given}: not a folder (give a folder of student folders)")
        if _is_single_student(folder):
            found.append((folder.resolve().parent, folder))
            continue
        for entry in sorted(folder.iterdir(), key=lambda p: p.name):
            if entry.name.startswith("."):
                continue
            if exclude is not None and _inside(entry, Path(exclude)):
                continue
            if not entry.is_dir():
                result.skipped.append(f"{entry}: not a folder")
            elif (entry / GRADES_MARKER).exists():
                result.skipped.append(f"{entry}: an output folder of `fossbot-hil grade`")
            else:
                found.append((folder, entry))
    seen: set[Path] = set()
    unique = []
    for parent, folder in found:
        key = folder.resolve()
        if key not in seen:
            seen.add(key)
            unique.append((parent, folder))
    result.students = _named(unique)
    if not any(s.kind != "none" for s in result.students):
        listed = ", ".join(str(d) for d in dirs)
        raise ConfigError(
            f"no students found in {listed}: expected one folder per student holding a "
            "colcon workspace (src/), a package (package.xml) or a node script (.py)"
        )
    return result
