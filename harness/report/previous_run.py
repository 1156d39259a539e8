"""What an earlier run left in a reused report folder, so a new run can clear it.

Old scenarios' files must not stay beside an index.html that no longer
lists them. Only the files the earlier summary.json names go (the folder
may hold the user's own), and only inside ``scenarios/``, so a tampered
summary cannot delete anything else.
"""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

SCENARIO_FOLDER = "scenarios"
SUMMARY = "summary.json"


def previous_files(root: Path) -> list[Path]:
    """The files an earlier run's summary.json lists under root/scenarios/, that exist."""
    try:
        summary = json.loads((root / SUMMARY).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    scenarios = summary.get("scenarios") if isinstance(summary, dict) else None
    if not isinstance(scenarios, list):
        return []
    folder = (root / SCENARIO_FOLDER).resolve()
    found = []
    for entry in scenarios:
        files = entry.get("files") if isinstance(entry, dict) else None
        for name in files.values() if isinstance(files, dict) else ():
            if not isinstance(name, str):
                continue
            path = root / name
            if path.parent.resolve() == folder and path.is_file() and not path.is_symlink():
                found.append(path)
    return found


def clear_previous_run(root: Path) -> int:
    """Remove the earlier run's scenario files; how many were removed."""
    removed = 0
    for path in previous_files(root):
        with contextlib.suppress(OSError):
            path.unlink()
            removed += 1
    return removed
