"""Locks that say who holds them: one run at a time on a ROS domain, a serial port, a folder.

A lock is an exclusive ``flock`` on a lock file. Right after taking it the
holder truncates the file and writes its pid, the time and its command line
into it, so a run that is refused can say who has the thing it wanted. The
kernel drops the lock when its holder dies, so a crashed run never leaves
anything locked; the stale record in a free file is overwritten (under the
lock) by the next holder. Lock files in a shared folder (the temp folder,
used by every user of the machine) are readable and writable by all and
reused forever; a lock file inside a folder of the user's own (a report
folder) can instead be removed on release, leaving the folder as it was.

Within one process a lock is held once: asking again fails, naming this
process, unless the caller asks for a re-entrant lock (the pytest plugin
holds a port or a domain for a test and the link inside takes it again),
which is then counted and freed by the last release.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Held", "Holder", "HolderLock", "held_here", "shared_folder", "take", "this_process"]

POLL_S = 0.05  # the kernel has no timed flock: retry this often until the deadline
RECORD_BYTES = 512  # the longest holder record read back
COMMAND_CHARS = 160  # the longest command line written into a record

_guard = threading.Lock()
# lock file -> [descriptor, holders in this process, remove the file on the last release]
_held: dict[str, list] = {}


@dataclass(frozen=True)
class Holder:
    """Who holds a lock, as its holder wrote it (pid None: not written yet, or unreadable)."""

    pid: int | None = None
    since: float | None = None  # time.time() when it took the lock
    command: str = ""

    def __str__(self) -> str:
        """'pid 123 (fossbot-hil run --domain-id 42), for 12 s', or 'another run'."""
        if self.pid is None:
            return "another run"
        command = f" ({self.command})" if self.command else ""
        held = f", for {max(0.0, time.time() - self.since):.0f} s" if self.since else ""
        return f"pid {self.pid}{command}{held}"

    @classmethod
    def parse(cls, text: str) -> Holder:
        """The record `record()` wrote: pid, time and command, one a line."""
        lines = text.split("\n")
        if len(lines) < 2 or not lines[0].isdigit():
            return cls()
        try:
            since: float | None = float(lines[1])
        except ValueError:
            since = None
        return cls(int(lines[0]), since, lines[2] if len(lines) > 2 else "")

    @staticmethod
    def record(command: str) -> bytes:
        """This process's record, holding since now."""
        command = command.replace("\n", " ")
        if len(command) > COMMAND_CHARS:
            command = command[: COMMAND_CHARS - 3] + "..."
        return f"{os.getpid()}\n{time.time():.3f}\n{command}\n".encode()


class Held(Exception):
    """The lock is held by someone else (or, not re-entrant, by this process already)."""

    def __init__(self, path: Path, holder: Holder) -> None:
        super().__init__(f"{path}: held by {holder}")
        self.path, self.holder = path, holder


def this_process() -> str:
    """This process, as the message of a run it keeps waiting names it."""
    worker = os.environ.get("PYTEST_XDIST_WORKER")  # inherited by the processes it starts
    if worker and "pytest" in sys.modules:
        return f"pytest worker {worker}"
    spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    program = os.path.basename(sys.argv[0])
    if spec is not None and spec.name == "harness.cli":  # python -m harness.cli
        program = "fossbot-hil"
    return " ".join([program, *sys.argv[1:]])


def shared_folder(folder: Path) -> Path:
    """A folder of lock files every user of this machine can add to (sticky, like /tmp)."""
    if not folder.is_dir():
        folder.mkdir(parents=True, exist_ok=True)
        with contextlib.suppress(OSError):  # made by another user a moment ago: theirs to set
            folder.chmod(0o1777)  # anyone may add a lock, only its owner remove it
    return folder


def _read_holder(handle: int) -> Holder:
    try:
        return Holder.parse(os.pread(handle, RECORD_BYTES, 0).decode(errors="replace"))
    except OSError:
        return Holder()


def _open(path: Path, shared: bool) -> int:
    handle = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
    if shared:
        with contextlib.suppress(OSError):  # another user's file: its owner made it shared
            os.fchmod(handle, 0o666)  # the umask must not lock other users out
    return handle


def _same_file(handle: int, path: Path) -> bool:
    """Is the locked file still the one at `path` (not removed by its last holder)?"""
    try:
        now = os.stat(path)
    except FileNotFoundError:
        return False
    mine = os.fstat(handle)
    return (mine.st_dev, mine.st_ino) == (now.st_dev, now.st_ino)


def held_here(path: Path) -> bool:
    """Does this process hold the lock on `path`?"""
    with _guard:
        return str(path) in _held


class HolderLock:
    """This process's hold on one lock file, until `release()` (or process exit)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._key: str | None = str(path)

    def fileno(self) -> int | None:
        """The locked descriptor while held (None after `release`). A process given a
        copy (fork, fd passing) holds the lock with us until its copy is closed."""
        with _guard:
            entry = _held.get(self._key) if self._key is not None else None
            return None if entry is None else entry[0]

    def release(self) -> None:
        """Let go; safe to call twice. The last holder in this process frees the lock."""
        key, self._key = self._key, None
        if key is None:
            return
        with _guard:
            entry = _held.get(key)
            if entry is None:
                return
            entry[1] -= 1
            if entry[1] > 0:
                return
            del _held[key]
            handle, _, remove = entry
            if remove:  # still locked, so no other run can be using this file now
                with contextlib.suppress(OSError):
                    os.unlink(key)
            os.close(handle)  # closing the only descriptor drops the flock

    def __enter__(self) -> HolderLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def take(
    path: Path,
    *,
    wait: float = 0.0,
    reentrant: bool = False,
    shared: bool = False,
    remove: bool = False,
    command: str | None = None,
) -> HolderLock:
    """Lock `path` (created if missing), waiting at most `wait` seconds for its holder.

    Raises `Held` naming the holder when the wait runs out, and OSError when
    the lock file cannot be opened. `shared`: the file is for every user of
    the machine (mode 0666, kept); `remove`: the file is deleted by the last
    release (for a lock file in a user's own folder). `command` describes
    this process in the record (default: its command line).
    """
    key = str(path)
    with _guard:
        entry = _held.get(key)
        if entry is not None:
            if not reentrant:
                raise Held(path, _read_holder(entry[0]))
            entry[1] += 1
            return HolderLock(path)
    deadline = time.monotonic() + max(0.0, wait)
    while True:
        handle = _open(path, shared)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read_holder(handle)
            os.close(handle)
            if time.monotonic() >= deadline:
                raise Held(path, holder) from None
            time.sleep(POLL_S)  # polling a bounded condition, not synchronising
            continue
        except BaseException:
            os.close(handle)
            raise
        if remove and not _same_file(handle, path):
            os.close(handle)  # its holder removed it as we locked: lock the new one
            continue
        break
    # Another user's file may be ours to lock but not to write: the lock is what counts.
    with contextlib.suppress(OSError):
        os.ftruncate(handle, 0)  # a record longer than ours must not leave its tail behind
        os.pwrite(handle, Holder.record(this_process() if command is None else command), 0)
    with _guard:
        _held[key] = [handle, 1, remove]
    return HolderLock(path)
