"""A launch file read by the reader of its kind, picked by its name; never run."""

from __future__ import annotations

from pathlib import Path

from harness.launch_files.entries import LaunchFile, Unread
from harness.launch_files.python_file import read_python
from harness.launch_files.xml_file import read_xml
from harness.launch_files.yaml_file import read_yaml

__all__ = ["MAX_BYTES", "is_launch_name", "read_launch_file"]

MAX_BYTES = 1 << 20  # a launch file is a page or two; a bigger one is not read
READERS = {".py": read_python, ".xml": read_xml, ".yaml": read_yaml, ".yml": read_yaml}


def is_launch_name(name: str) -> bool:
    """Could a file of this name in a launch/ folder be a launch file?"""
    return Path(name).suffix in READERS and not name.startswith((".", "_", "~"))


def read_launch_file(path: Path, shown: str) -> LaunchFile | None:
    """What the file at `path` (shown to the user as `shown`) says; None when it is no
    launch file (a helper module, a parameter file kept in launch/)."""
    reader = READERS.get(path.suffix)
    if reader is None:
        return None
    try:
        if path.stat().st_size > MAX_BYTES:
            problem = f"is larger than {MAX_BYTES >> 20} MB: not read"
            return LaunchFile(path, shown, unread=(Unread(1, problem),))
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        reason = getattr(err, "strerror", None) or " ".join(str(err).split())
        return LaunchFile(path, shown, unread=(Unread(1, f"cannot be read: {reason}"),))
    try:
        return reader(text, path, shown)
    except (RecursionError, MemoryError):  # nested past the parser's limits
        return LaunchFile(path, shown, unread=(Unread(1, "is nested too deeply to be read"),))
