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
from collections.abc import Mapping, Sequence
from pathlib import Path

from harness.errors import OptionError
from harness.option_names import escaped

COLUMNS = (
    "key", "scenario", "faults", "seed", "threshold", "verdict", "ticks", "failed_ticks",
    "first_failure", "wall_s", "worker",
)  # fmt: skip


def columns_for(varied: Sequence[str] = ()) -> tuple[str, ...]:
    """The table's columns: each generated variation's level after the threshold."""
    at = COLUMNS.index("threshold") + 1
    return (*COLUMNS[:at], *varied, *COLUMNS[at:])


def read_header(path: Path) -> tuple[str, ...]:
    with open(path, encoding="utf-8", errors="replace", newline="") as handle:
        return tuple(next(csv.reader(handle), []))


def read_rows(path: Path) -> list[dict[str, str]]:
    """The complete rows of a results file (a partly written last line is left out)."""
    if not path.exists():
        return []
    text = path.read_text(encoding="utf-8", errors="replace")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]  # the row a kill cut short
    rows = list(csv.DictReader(io.StringIO(text)))
    return [row for row in rows if row.get("key") and row.get("verdict")]


def check_columns(path: Path, columns: Sequence[str]) -> None:
    """Resuming needs the table's own columns (the same generated variations)."""
    if read_header(path) != tuple(columns):
        found = f"{path} has the columns {', '.join(read_header(path))[:300]}"
        raise OptionError(
            "resume",
            f"{{resume}}: {escaped(found)}; this sweep writes {escaped(', '.join(columns))}"
            " (another {vary}? use another {out})",
        )


def rows_to_resume(path: Path, columns: Sequence[str] = COLUMNS) -> list[dict[str, str]]:
    """The finished rows of a table to resume (none when there is no table yet)."""
    if not path.exists():
        return []
    check_columns(path, columns)
    return read_rows(path)


class ResultsTable:
    """Appends rows to ``path``; `done` holds the keys of every run already there.

    Resuming needs the same columns (the same generated variations): a table
    of another campaign is refused rather than mixed with this one.
    """

    def __init__(self, path: Path, *, resume: bool, columns: Sequence[str] = COLUMNS) -> None:
        self.path = path
        self.columns = tuple(columns)
        resuming = resume and path.exists()
        rows = rows_to_resume(path, self.columns) if resuming else []
        self.done = {row["key"] for row in rows}
        self.rows = rows
        path.parent.mkdir(parents=True, exist_ok=True)
        if not resuming:
            self._write(self._line(dict(zip(self.columns, self.columns, strict=True))), mode="w")
        else:
            self._trim()

    def add(self, row: Mapping[str, object]) -> None:
        """Append one finished run, durably, unless its key is there already."""
        key = str(row["key"])
        if key in self.done:
            return  # a retried task that had finished after all: one row per run
        self.done.add(key)
        self.rows.append({c: str(row.get(c, "")) for c in self.columns})
        self._write(self._line(row), mode="a")

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

    def _line(self, row: Mapping[str, object]) -> str:
        out = io.StringIO()
        csv.writer(out, lineterminator="\n").writerow([row.get(c, "") for c in self.columns])
        return out.getvalue()
