"""Writing report files atomically: a crash never leaves half a file under its name."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def write_atomically(path: str | Path, data: bytes) -> Path:
    """Write to a temporary file beside `path`, fsync, then rename over it."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return target


def relative_path(path: str | Path, folder: str | Path) -> str:
    """`path` as seen from `folder` (POSIX separators), for links inside report files."""
    return Path(os.path.relpath(Path(path).resolve(), Path(folder).resolve())).as_posix()
