"""Reading a user's text file (a scenario, a grading file, a roster): bounded, and safe.

A regular file only, opened without blocking (a FIFO or a device named by
mistake never hangs the command), at most `limit` bytes, UTF-8; every problem
is one ConfigError line (exit 2) that names the file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from harness.errors import ConfigError

__all__ = ["read_text_file"]


def read_text_file(path: str | Path, *, limit: int, name: str, kind: str) -> str:
    """The text of `path`; `name` starts every error, `kind` says what the file should be
    ("scenario file", "grading file", ...)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise ConfigError(f"{name}: no such {kind}") from None
    except (OSError, ValueError) as err:
        reason = getattr(err, "strerror", None) or err
        raise ConfigError(f"{name}: cannot read: {reason}") from None
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{name}: is a folder, not a {kind}")
    if not stat.S_ISREG(mode):
        raise ConfigError(f"{name}: not a regular file")
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY)
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced since the stat above
                raise ConfigError(f"{name}: not a regular file")
            with os.fdopen(os.dup(fd), "rb") as handle:
                data = handle.read(limit + 1)
        finally:
            os.close(fd)
    except OSError as err:
        raise ConfigError(f"{name}: cannot read: {err.strerror or err}") from None
    if len(data) > limit:
        raise ConfigError(f"{name}: larger than {limit >> 20} MiB; not a {kind}")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise ConfigError(
            f"{name}: not UTF-8 text (byte 0x{data[err.start]:02x} at line {line})"
        ) from None
