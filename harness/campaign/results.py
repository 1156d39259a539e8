"""A campaign's results table: one CSV row per finished run, written as it finishes.

Each row is appended and flushed to disk (fsync) the moment its run is
done, so a campaign killed at any point keeps every finished run; a row
cut short by the kill is not a row (``done`` reads only complete ones),
and ``--resume`` runs only what is missing. Pure: csv and os only.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping
from pathlib import Path

COLUMNS = (
    "key",
    "scenario",
    "faults",
    "seed",
    "threshold",
    "verdict",
    "ticks",
    "failed_ticks",
    "first_failure",
    "wall_s",
    "worker",
)


def read_rows(path: Path) -> list[dict[str, str]]:
    """The complete rows of a results file (a partly written last line is left out)."""
    if not path.exists():
        return []
    text = path.read_text(encoding="utf-8", errors="replace")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]  # the row a kill cut short
    rows = list(csv.DictReader(io.StringIO(text)))
    return [row for row in rows if row.get("key") and row.get("verdict")]


class ResultsTable:
    """Appends rows to ``path``; `done` holds the keys of every run already there."""

    def __init__(self, path: Path, *, resume: bool) -> None:
        self.path = path
        rows = read_rows(path) if resume else []
        self.done = {row["key"] for row in rows}
        self.rows = rows
        path.parent.mkdir(parents=True, exist_ok=True)
        if not resume or not path.exists():
            self._write(_line(dict(zip(COLUMNS, COLUMNS, strict=True))), mode="w")
        else:
            self._trim()

    def add(self, row: Mapping[str, object]) -> None:
        """Append one finished run, durably, unless its key is there already."""
        key = str(row["key"])
        if key in self.done:
            return  # a retried task that had finished after all: one row per run
        self.done.add(key)
        self.rows.append({c: str(row.get(c, "")) for c in COLUMNS})
        self._write(_line(row), mode="a")

    def _trim(self) -> None:
        """Drop a last line a kill cut short, so appended rows start on a line of their own."""
        data = self.path.read_bytes()
        if data and not data.endswith(b"\n"):
            with open(self.path, "r+b") as handle:
                handle.truncate(data.rfind(b"\n") + 1)

    def _write(self, text: str, *, mode: str) -> None:
        with open(self.path, mode, encoding="utf-8", newline="") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())


def _line(row: Mapping[str, object]) -> str:
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow([row.get(c, "") for c in COLUMNS])
    return out.getvalue()
