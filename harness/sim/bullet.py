"""The one place that imports pybullet and connects to it, without its banner.

pybullet's C code prints "pybullet build time: ..." through C stdio when it
loads and again on every connect; it sits in C's buffer and surfaces at exit,
in the middle of a report or of a tool reading our stdout. Both are swallowed
here by pointing file descriptor 1 at /dev/null and flushing C stdio.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def _stdout_silenced() -> Iterator[None]:
    """Point fds 1 and 2 at /dev/null (the banner's stream varies with buffering)."""
    sys.stdout.flush()
    sys.stderr.flush()
    _LIBC.fflush(None)
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    try:
        with open(os.devnull, "wb") as devnull:
            for fd in saved:
                os.dup2(devnull.fileno(), fd)
            try:
                yield
            finally:
                _LIBC.fflush(None)
    finally:
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)


with _stdout_silenced():
    import pybullet as pb


def connect(gui: bool = False) -> int:
    """A new physics client (DIRECT, or the GUI viewer) with its own id."""
    with _stdout_silenced():
        return pb.connect(pb.GUI if gui else pb.DIRECT)


__all__ = ["connect", "pb"]
