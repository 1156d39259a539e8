"""Writing report files atomically: a crash never leaves half a file under its name.

Every file is first written to a hidden temporary file beside its final
name, ``.<name>.hil-<pid>-<random>.tmp``, then fsynced and renamed over
it. The temporary file is created with mode 0666 and the kernel applies
the umask, so reports get the modes any other tool's files get (0644
under umask 022), not mkstemp's 0600. A process killed mid-write
(SIGKILL, power loss) cannot remove its temporary file; the pid in the
name lets the next write into that folder recognise it and remove it
once that process is gone.
"""

from __future__ import annotations

import os
import re
import secrets
from collections.abc import Callable
from pathlib import Path

__all__ = [
    "TEMPORARY_NAME",
    "fill_atomically",
    "relative_path",
    "remove_stale_temporaries",
    "write_atomically",
]

_NAME_CHARS = 100  # of the final name, in a temporary's name (file names have 255 at most)
_swept: set[str] = set()  # folders this process has cleared of stale temporaries
#: A writer's hidden temporary file; its pid says whether its writer may still run.
TEMPORARY_NAME = re.compile(r"\..*\.hil-(?P<pid>[0-9]+)-[0-9a-f]{8}\.tmp(?:\.[A-Za-z0-9]+)?")


def _running(pid: int) -> bool:
    """A process with this pid exists (perhaps another user's)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_temporaries(folder: str | Path) -> list[Path]:
    """Remove the temporary files left in `folder` by writers no longer running; return them."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        match = TEMPORARY_NAME.fullmatch(entry.name)
        if match is None:
            continue
        pid = int(match["pid"])
        if pid == os.getpid() or _running(pid):
            continue
        try:
            os.unlink(entry.path)
        except OSError:
            continue  # gone already, or not ours to remove
        removed.append(Path(entry.path))
    return removed


def _new_temporary(target: Path, suffix: str) -> Path:
    """Create an empty hidden temporary file beside `target` (mode 0666 less the umask)."""
    for _ in range(100):
        token = secrets.token_hex(4)
        name = f".{target.name[:_NAME_CHARS]}.hil-{os.getpid()}-{token}.tmp{suffix}"
        path = target.with_name(name)
        try:
            handle = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
        except FileExistsError:
            continue
        os.close(handle)
        return path
    raise FileExistsError(f"{target.parent}: no free temporary file name")


def _fsync(path: Path) -> None:
    handle = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    try:
        os.fsync(handle)
    finally:
        os.close(handle)


def fill_atomically(
    path: str | Path, fill: Callable[[Path], str | Path | None], *, suffix: str = ""
) -> Path:
    """Let `fill` write a fresh temporary file beside `path`; fsync it, rename it over `path`.

    `suffix` ends the temporary's name (for writers that go by it). When
    `fill` returns a path other than the temporary, it chose where to
    write: the temporary is removed and that path returned. On any
    failure the temporary is removed. Stale temporary files of writers
    that were killed are removed from the folder first (once per folder
    and process: a run writes many files into one folder).
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    folder = str(target.parent.resolve())
    if folder not in _swept:
        remove_stale_temporaries(folder)
        _swept.add(folder)
    temporary = _new_temporary(target, suffix)
    try:
        written = fill(temporary)
        if written is not None and Path(written) != temporary:
            temporary.unlink(missing_ok=True)
            return Path(written)
        _fsync(temporary)
        os.replace(temporary, target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return target


def write_atomically(path: str | Path, data: bytes) -> Path:
    """Write `data` to `path` through a temporary file beside it (see `fill_atomically`)."""

    def fill(temporary: Path) -> None:
        with open(temporary, "wb") as out:
            out.write(data)

    return fill_atomically(path, fill)


def relative_path(path: str | Path, folder: str | Path) -> str:
    """`path` as seen from `folder` (POSIX separators), for links inside report files."""
    return Path(os.path.relpath(Path(path).resolve(), Path(folder).resolve())).as_posix()
