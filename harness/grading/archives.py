"""Archived hand-ins (.zip, .tar.gz, ...): unpacked safely, then graded as folders are.

Pure: the standard library only. The rules, also in docs/grading.md:

- An archive in a DIR is **one student**, named after the archive (alex.tar.gz
  is "alex"). It is unpacked into ``OUT/unpacked/<name>/``; when it holds a
  single top folder (other than ``src/``), the hand-in is that folder.
- An archive given as a DIR is a **class archive**: read as the folder it
  unpacks to (a folder of students, or one student named after the archive).
  The archives in it are its students' archives and are unpacked in turn.
- Nothing is written outside the archive's folder: a member with an absolute
  name or one that climbs out with ``..`` refuses the archive; links
  (symbolic or hard) are never made (they are left out, and named in the
  student's reason when no node is found); device files, fifos and other
  special members refuse the archive; so do encrypted zip members and zip
  compression other than stored or deflate (bzip2 and lzma members can
  expand without bound in one step).
- The limits are counted while the bytes are read, never taken from the
  archive's headers: a zip bomb lies in its headers.
- A refused or unreadable archive is a row with its reason, and nothing of
  it is left unpacked.

Call `unpack_submissions` only once the output folder is the grader's (locked):
it writes there.
"""

from __future__ import annotations

import bz2
import gzip
import lzma
import os
import posixpath
import shutil
import stat
import tarfile
import zipfile
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import IO

from harness.grading.discover import (
    Discovery,
    Entry,
    Student,
    add_folder,
    named,
    passed_over,
    slugify,
)

__all__ = [
    "CLASS_LIMITS",
    "MAX_FILE_BYTES",
    "STUDENT_LIMITS",
    "UNPACKED",
    "Limits",
    "Refused",
    "unpack",
    "unpack_submissions",
]

UNPACKED = "unpacked"  # OUT/unpacked/<name>/: the archives' contents
MB = 1 << 20
MAX_FILE_BYTES = 100 * MB  # one file of an archive
MAX_STUDENT_BYTES = 200 * MB  # everything one student's archive unpacks to
MAX_STUDENT_MEMBERS = 20_000  # files, folders and links in one student's archive
MAX_CLASS_BYTES = 2048 * MB  # a class archive (its students' archives inside count once)
MAX_CLASS_MEMBERS = 200_000
CHUNK = 1 << 16
TAR_HEADER_SLACK = 2048  # bytes of tar headers and padding allowed per member
MAX_SHOWN_LINKS = 3


@dataclass(frozen=True)
class Limits:
    """How much one archive may unpack to."""

    total_bytes: int
    members: int
    file_bytes: int = MAX_FILE_BYTES
    what: str = "one student's archive"


STUDENT_LIMITS = Limits(MAX_STUDENT_BYTES, MAX_STUDENT_MEMBERS)
CLASS_LIMITS = Limits(MAX_CLASS_BYTES, MAX_CLASS_MEMBERS, what="a class archive")


class Refused(Exception):
    """An archive that was not unpacked; the message is the student's reason."""


def _show(name: str) -> str:
    """A member's name as a reason quotes it (the student chose it: repr escapes it)."""
    return repr(name if len(name) <= 120 else name[:117] + "...")


def _mb(count: int) -> str:
    return f"{count // MB} MB"


@dataclass
class _Budget:
    """What one archive has unpacked so far, against its limits."""

    limits: Limits
    members: int = 0
    total: int = 0
    links: list[str] = field(default_factory=list)  # members that are links: left out

    def member(self, count: int = 1) -> None:
        self.members += count
        if self.members > self.limits.members:
            raise Refused(
                f"archive refused: more than {self.limits.members:,} files and folders "
                f"(the limit for {self.limits.what})"
            )

    def expect(self, name: str, size: int) -> None:
        """Refuse at once what a header already says is too big; the reading counts anyway."""
        self._check(name, size, self.total + size)

    def add(self, name: str, count: int, file_so_far: int) -> None:
        """`count` more bytes read, `file_so_far` of them of the file `name`."""
        self.total += count
        self._check(name, file_so_far, self.total)

    def _check(self, name: str, file_bytes: int, total: int) -> None:
        if file_bytes > self.limits.file_bytes:
            raise Refused(
                f"archive refused: {_show(name)} unpacks to more than "
                f"{_mb(self.limits.file_bytes)} (the limit for one file)"
            )
        if total > self.limits.total_bytes:
            raise Refused(too_big(self.limits))


def too_big(limits: Limits) -> str:
    """The reason for an archive that unpacks to more than it may."""
    limit = _mb(limits.total_bytes)
    return f"archive refused: it unpacks to more than {limit} (the limit for {limits.what})"


def _target(dest: Path, name: str) -> Path | None:
    """Where member `name` goes below `dest`; None for one not unpacked (the root, __MACOSX)."""
    if name.startswith("/"):
        raise Refused(f"archive refused: {_show(name)} is an absolute path")
    norm = posixpath.normpath(name)
    if norm == ".." or norm.startswith("../"):
        raise Refused(f"archive refused: {_show(name)} would be written outside the submission")
    parts = norm.split("/")
    if norm == "." or parts[0] == "__MACOSX":  # macOS's resource forks: never code
        return None
    target = dest.joinpath(*parts)
    try:  # no links are ever made below dest, but check where it really is
        target.resolve().relative_to(dest.resolve())
    except ValueError:
        raise Refused(
            f"archive refused: {_show(name)} would be written outside the submission"
        ) from None
    return target


def _copy(source: IO[bytes], target: Path, name: str, budget: _Budget, executable: bool) -> None:
    """One regular file, counted as it is read; never through a link."""
    target.parent.mkdir(parents=True, exist_ok=True)
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_NOFOLLOW", 0)
    written = 0
    with open(os.open(target, flags, 0o755 if executable else 0o644), "wb") as out:
        while chunk := source.read(CHUNK):
            written += len(chunk)
            budget.add(name, len(chunk), written)
            out.write(chunk)


SPECIAL = {
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFIFO: "a fifo",
    stat.S_IFSOCK: "a socket",
}


def _unpack_zip(archive: Path, dest: Path, budget: _Budget) -> None:
    with zipfile.ZipFile(archive) as zipped:
        infos = zipped.infolist()
        budget.member(len(infos))  # the central directory lists what there is to unpack
        for info in infos:
            name = info.filename.replace("\\", "/")  # some Windows tools write backslashes
            target = _target(dest, name)
            if target is None:
                continue
            mode = info.external_attr >> 16 if info.create_system == 3 else 0
            kind = stat.S_IFMT(mode)
            if kind == stat.S_IFLNK:
                budget.links.append(name)
            elif info.is_dir() or kind == stat.S_IFDIR:
                target.mkdir(parents=True, exist_ok=True)
            elif kind not in (0, stat.S_IFREG):
                raise Refused(
                    f"archive refused: {_show(name)} is {SPECIAL.get(kind, 'not a regular file')}"
                )
            elif info.flag_bits & 0x1:
                raise Refused(f"archive refused: {_show(name)} is encrypted")
            elif info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                raise Refused(
                    f"archive refused: {_show(name)} is compressed with method "
                    f"{info.compress_type} (only stored and deflate members are unpacked)"
                )
            else:
                budget.expect(name, info.file_size)
                with zipped.open(info) as source:
                    _copy(source, target, name, budget, executable=bool(mode & stat.S_IXUSR))


class _Capped:
    """A stream that refuses to give more than `cap` bytes (tar headers can make tarfile
    read any amount; a pax header is read whole)."""

    def __init__(self, stream: IO[bytes], cap: int, limits: Limits) -> None:
        self.stream, self.cap, self.limits, self.read_bytes = stream, cap, limits, 0

    def read(self, size: int = -1) -> bytes:
        room = self.cap + 1 - self.read_bytes
        data = self.stream.read(room if size < 0 else min(size, room))
        self.read_bytes += len(data)
        if self.read_bytes > self.cap:
            raise Refused(too_big(self.limits))
        return data


def _decompressed(raw: IO[bytes]) -> IO[bytes]:
    """The tar stream inside `raw`, by its first bytes: gzip, bzip2, xz or none."""
    magic = raw.read(6)
    raw.seek(0)
    if magic.startswith(b"\x1f\x8b"):
        return gzip.GzipFile(fileobj=raw)
    if magic.startswith(b"BZh"):
        return bz2.BZ2File(raw)
    if magic == b"\xfd7zXZ\x00":
        return lzma.LZMAFile(raw)
    return raw


def _tar_kind(member: tarfile.TarInfo) -> str:
    if member.ischr():
        return "a character device"
    if member.isblk():
        return "a block device"
    if member.isfifo():
        return "a fifo"
    return "not a regular file"


def _unpack_tar(archive: Path, dest: Path, budget: _Budget) -> None:
    limits = budget.limits
    cap = limits.total_bytes + limits.members * TAR_HEADER_SLACK + MB
    with open(archive, "rb") as raw, _decompressed(raw) as inner:
        stream = _Capped(inner, cap, limits)
        # "r|": read as a stream, member after member; never a seek back
        with tarfile.open(fileobj=stream, mode="r|") as tar:  # type: ignore[call-overload]
            for member in tar:
                budget.member()
                target = _target(dest, member.name)
                if target is None:
                    continue
                if member.issym() or member.islnk():
                    budget.links.append(member.name)
                    continue
                if not (member.isdir() or member.isreg()):
                    raise Refused(f"archive refused: {_show(member.name)} is {_tar_kind(member)}")
                _data_filter(member, dest)
                if member.isdir():
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                budget.expect(member.name, member.size)
                source = tar.extractfile(member)
                assert source is not None  # a regular file
                executable = bool(member.mode & stat.S_IXUSR)
                _copy(source, target, member.name, budget, executable)


def _data_filter(member: tarfile.TarInfo, dest: Path) -> None:
    """tarfile's own 'data' filter (Python 3.11.4+, 3.10.12+) as a second opinion."""
    check = getattr(tarfile, "data_filter", None)
    if check is None:
        return
    try:
        check(member, str(dest))
    except tarfile.TarError as err:  # FilterError
        raise Refused(
            f"archive refused: {_show(member.name)} is refused by tarfile's data filter "
            f"({type(err).__name__})"
        ) from None


def unpack(archive: Path, dest: Path, limits: Limits = STUDENT_LIMITS) -> list[str]:
    """Unpack `archive` into the folder `dest` (made anew); the links that were left out.

    Refused says why it was not unpacked (refused, or it could not be read);
    then nothing of it is left in `dest`. A .zip is read as a zip file, any
    other archive name as a tar file (compressed or not).
    """
    budget = _Budget(limits)
    shutil.rmtree(dest, ignore_errors=True)
    try:
        dest.mkdir(parents=True)
        found = archive.stat()
        if not stat.S_ISREG(found.st_mode):  # a fifo named x.zip would block the read
            raise Refused("archive could not be unpacked: not a regular file")
        size = found.st_size
        if size > limits.total_bytes:  # packed bigger than it may unpack to
            raise Refused(
                f"archive refused: it is {_mb(size)}, more than the {_mb(limits.total_bytes)} "
                f"{limits.what} may unpack to"
            )
        if archive.name.casefold().endswith(".zip"):
            _unpack_zip(archive, dest, budget)
        else:
            _unpack_tar(archive, dest, budget)
    except Refused:
        shutil.rmtree(dest, ignore_errors=True)
        raise
    except Exception as err:  # noqa: BLE001 - a bad archive is its student's row, not the end
        shutil.rmtree(dest, ignore_errors=True)  # BadZipFile, TarError, zlib.error, EOFError...
        why = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise Refused(f"archive could not be unpacked: {why or type(err).__name__}") from None
    return budget.links


def _links_note(links: list[str]) -> str:
    if not links:
        return ""
    shown = ", ".join(_show(n) for n in links[:MAX_SHOWN_LINKS])
    more = f" and {len(links) - MAX_SHOWN_LINKS} more" if len(links) > MAX_SHOWN_LINKS else ""
    return f"links in the archive are not unpacked: {shown}{more}"


def _looked_through(folder: Path) -> Path:
    """The folder the hand-in is in: through lone wrapper folders (but never into src/)."""
    while True:
        visible = [p for p in folder.iterdir() if not passed_over(p.name)]
        if len(visible) != 1 or visible[0].name == "src":
            return folder
        only = visible[0]
        if only.is_symlink() or not only.is_dir():
            return folder
        folder = only


class _Folders:
    """Unique folder names below `into`."""

    def __init__(self, into: Path) -> None:
        self.into = into
        self.taken: set[str] = set()

    def new(self, name: str) -> Path:
        slug = base = slugify(name)
        n = 2
        while slug.casefold() in self.taken:
            slug, n = f"{base}-{n}", n + 1
        self.taken.add(slug.casefold())
        return self.into / slug


def _unpacked_student(archive: Entry, folders: _Folders) -> Entry:
    """One student's archive, unpacked: the folder to look at, or the reason there is none."""
    dest = folders.new(archive.name)
    try:
        links = unpack(archive.path, dest, STUDENT_LIMITS)
    except Refused as err:
        return replace(archive, problem=str(err))
    return replace(archive, path=_looked_through(dest), note=_links_note(links))


def _add_class_archive(archive: Entry, folders: _Folders, result: Discovery) -> None:
    """A class archive, unpacked and read as the folder it holds, into `result`."""
    dest = folders.new(archive.name)
    try:
        links = unpack(archive.path, dest, CLASS_LIMITS)
    except Refused as err:
        result.entries.append(replace(archive, problem=str(err)))
        return
    root = _looked_through(dest)
    before = len(result.entries) + len(result.archives)
    add_folder(result, root, name=archive.name, where=archive.where, file=archive.file)
    if len(result.entries) + len(result.archives) == before:
        reason = "no submission in the class archive: it holds no folder, archive or file"
        note = _links_note(links)
        result.entries.append(replace(archive, problem=f"{reason}; {note}" if note else reason))


def unpack_submissions(found: Discovery, into: Path) -> list[Student]:
    """Every student of `found`: its folders and files, and its archives unpacked below `into`.

    All are named together (discover.named): an archive's student and a
    folder's student of one name get their DIR's name, as two folders do.
    A refused or unreadable archive is a student with its reason. Notes of
    what was passed over inside class archives are added to `found.skipped`.
    """
    folders = _Folders(Path(os.path.abspath(into)))  # workers may run elsewhere (cwd)
    inside = Discovery()
    for archive in found.class_archives:
        _add_class_archive(archive, folders, inside)
    entries = [*found.entries, *inside.entries]
    entries += [_unpacked_student(a, folders) for a in [*found.archives, *inside.archives]]
    found.skipped += inside.skipped
    return named(entries)
