"""The class roster (`grade --roster FILE`): which submission folder is which student (pure).

A CSV with a header row naming at least `folder` and `id` (`name` optional;
columns are matched without regard to case or spaces, and `student` is taken
for `folder`)::

    folder,id,name
    alex,s1234,Alex Kowalski
    bea_zip,s1235,Beata Nowak

`folder` is the submission's name as grade shows it: the folder's name, or
an archive's name without .zip/.tar.gz. Every roster entry gets a row, a
submission or not; submissions not on the roster keep their row, with no id,
and are listed once on the terminal.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

from harness.errors import ConfigError
from harness.option_names import named
from harness.text_file import read_text_file

__all__ = ["Roster", "RosterEntry", "load_roster"]

MAX_ROSTER_BYTES = 4 << 20
FOLDER_COLUMNS = ("folder", "student", "submission")


@dataclass(frozen=True)
class RosterEntry:
    folder: str
    id: str
    name: str = ""


@dataclass(frozen=True)
class Roster:
    entries: tuple[RosterEntry, ...]
    source: str = ""

    def by_folder(self) -> dict[str, RosterEntry]:
        return {e.folder.casefold(): e for e in self.entries}

    def entry_for(self, submission: str) -> RosterEntry | None:
        """The roster line of a submission named `submission` (a folder name; `mon/alex` for
        a name given in two DIRs is looked up as `alex` too)."""
        table = self.by_folder()
        key = submission.casefold()
        return table.get(key) or table.get(key.rsplit("/", 1)[-1])


def _column(header: list[str], names: tuple[str, ...]) -> int | None:
    cleaned = [h.strip().casefold().replace(" ", "_") for h in header]
    for name in names:
        if name in cleaned:
            return cleaned.index(name)
    return None


def parse_roster(text: str, source: str | None = None) -> Roster:
    """The roster in CSV `text`; ConfigError naming the line for anything ambiguous."""
    source = source or named("roster")
    rows = list(csv.reader(io.StringIO(text.lstrip("\ufeff"))))  # Excel writes a BOM
    rows = [r for r in rows if any(cell.strip() for cell in r)]
    if not rows:
        raise ConfigError(f"{source}: empty (expected a header row: folder,id,name)")
    header = rows[0]
    folder_at = _column(header, FOLDER_COLUMNS)
    id_at = _column(header, ("id", "student_id", "id_number"))
    name_at = _column(header, ("name", "full_name"))
    if folder_at is None or id_at is None:
        raise ConfigError(
            f"{source}: the header row must name the columns folder and id "
            f"(found: {', '.join(h.strip() for h in header)[:200]})"
        )
    entries: list[RosterEntry] = []
    folders: dict[str, int] = {}
    ids: dict[str, int] = {}
    for line, row in enumerate(rows[1:], start=2):
        cells = [c.strip() for c in row]

        def cell(at: int | None, cells: list[str] = cells) -> str:
            return cells[at] if at is not None and at < len(cells) else ""

        folder, student_id = cell(folder_at), cell(id_at)
        if not folder or not student_id:
            raise ConfigError(f"{source} line {line}: every row needs a folder and an id")
        for kind, value, seen in (("folder", folder, folders), ("id", student_id, ids)):
            if value.casefold() in seen:
                raise ConfigError(
                    f"{source} line {line}: {kind} {value!r} is also on line "
                    f"{seen[value.casefold()]}"
                )
            seen[value.casefold()] = line
        entries.append(RosterEntry(folder, student_id, cell(name_at)))
    return Roster(tuple(entries), source)


def load_roster(path: str | Path) -> Roster:
    """The roster file at `path`; ConfigError (exit 2) when it cannot be read or is ambiguous."""
    source = f"{named('roster')} {path}"
    text = read_text_file(path, limit=MAX_ROSTER_BYTES, name=source, kind="roster (CSV)")
    return parse_roster(text, source)
