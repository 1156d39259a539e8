"""The one place that imports pybullet and connects to it, without its banner.

pybullet's C code prints "pybullet build time: ..." through C stdio when it
loads and again on every connect; it sits in C's buffer and surfaces at exit,
in the middle of a report or of a tool reading our stdout. Both are swallowed
here by pointing file descriptors 1 and 2 at a temporary file and flushing C stdio.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import tempfile
from collections.abc import Iterator

from harness.ctrl_c import stops_held

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def captured_output() -> Iterator[list[str]]:
    """Send fds 1 and 2 to a temporary file; afterwards the list holds what was written
    (PyBullet's loaders print their errors instead of raising them)."""
    lines: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    _LIBC.fflush(None)
    # Held: a Ctrl-C inside would leave fds 1 and 2 here, and the summary after it lost.
    with stops_held(), tempfile.TemporaryFile() as capture:  # unlinked at once
        saved = {fd: os.dup(fd) for fd in (1, 2)}
        try:
            for fd in saved:
                os.dup2(capture.fileno(), fd)
            yield lines
        finally:
            _LIBC.fflush(None)
            for fd, copy in saved.items():
                os.dup2(copy, fd)
                os.close(copy)
            capture.seek(0)
            text = capture.read(1 << 20).decode("utf-8", "replace")
            lines.extend(line.strip() for line in text.splitlines() if line.strip())


def last_complaint(lines: list[str]) -> str:
    """PyBullet's last error or warning among captured lines, without its source location."""
    for line in reversed(lines):
        text = line.split("]:", 1)[1].strip() if line.startswith("b3") and "]:" in line else line
        if text:
            return text[:200]
    return ""


with captured_output():  # the banner, thrown away
    import pybullet as pb


_SPARE: list[int] = []  # DIRECT clients emptied by `release`, ready for the next world


def connect(gui: bool = False) -> int:
    """A physics client (DIRECT, or the GUI viewer) of the caller's alone, with nothing in
    it: a released DIRECT one again, emptied (connecting costs 10 ms a world)."""
    if not gui and _SPARE:
        return _SPARE.pop()
    with captured_output():
        return pb.connect(pb.GUI if gui else pb.DIRECT)


def release(client: int, *, gui: bool = False) -> None:
    """Done with `client`: a DIRECT one is emptied and kept (one at most), a GUI one closed."""
    try:
        if gui or _SPARE:
            pb.disconnect(physicsClientId=client)
        else:
            pb.resetSimulation(physicsClientId=client)
            _SPARE.append(client)
    except pb.error:
        pass


__all__ = ["captured_output", "connect", "last_complaint", "pb", "release"]
