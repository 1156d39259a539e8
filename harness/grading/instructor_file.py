"""Reading an instructor's file (grading file, roster): bounded, UTF-8, one-line errors."""

from __future__ import annotations

from pathlib import Path

from harness.errors import ConfigError

__all__ = ["read_instructor_file"]


def read_instructor_file(path: str | Path, limit: int, where: str) -> str:
    """The text of `path`, at most `limit` bytes; ConfigError (exit 2) starting with
    `where` (e.g. "--roster r.csv") when it cannot be read, is larger, or is not UTF-8."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as err:
        raise ConfigError(f"{where}: {err.strerror or err}") from None
    if len(data) > limit:
        raise ConfigError(f"{where}: larger than {limit // 1024} KB")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError(f"{where}: not UTF-8 text (save it as UTF-8)") from None
