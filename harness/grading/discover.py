"""Which folders are students, and what each one handed in (pure: files only).

The rules, also in docs/grading.md:

- A folder given on the command line is **one student** when it is itself a
  colcon workspace or package, or when it has no subfolders and holds one
  node script. Otherwise **each subfolder is a student**, and **each archive**
  (.zip, .tar.gz, .tgz, .tar, ...) is a student named after the archive, to be
  unpacked once the output folder is the grader's (harness.grading.archives).
  Any other file is a student with the reason it is not graded. Hidden
  entries, file managers' litter (__MACOSX, Thumbs.db) and the grader's own
  output folder are passed over. An archive given on the command line is
  read as the folder it unpacks to.
- A student folder is a **package** when it has a package.xml at its top; a
  **workspace** when package.xml files sit below it (only under src/ if it
  has one; build/, install/, log/, hidden folders and folders holding a
  COLCON_IGNORE are never searched, at most four levels deep); a **script**
  when it has no package.xml and one top-level .py file, or several of which
  exactly one imports rclpy. Anything else is still a student, with the
  reason there is nothing to run.
"""

from __future__ import annotations

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
    """The students found, the archives still to unpack, and what was passed over (with why).

    `students` are the folder (and loose file) students, named among themselves;
    archives.unpack_submissions names them again together with the archives' students.
    """

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
    """A folder given to grade (or a class archive unpacked), into `result`.

    One student (`name`, found in `where`) when the folder is one hand-in;
    otherwise each entry is: a subfolder a student, an archive a student to
    unpack, another file a row saying why it is not graded.
    """
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
    """The students in `dirs`; ConfigError (exit 2) for a missing folder or no student at all.

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
    if not some_archive and not any(s.kind != "none" for s in result.students):
        listed = ", ".join(str(d) for d in dirs)
        raise ConfigError(
            f"no students found in {listed}: expected one folder (or archive) per student "
            "holding a colcon workspace (src/), a package (package.xml) or a node script (.py)"
        )
    return result
