"""A gradebook CSV that both Moodle's and Canvas's grade import take (pure).

What each import needs (from their importers' code and documentation):

- **Canvas** (Grades > Import) reads a header row whose first cell names the
  student (``Student``), whose second is Canvas's own user ``ID``, optionally
  followed by ``SIS User ID`` and ``SIS Login ID``, and then ``Section``; every
  column after those is an assignment, matched by its title (or ``Title
  (assignment id)``), a new title making a new assignment. A student is found
  by the ``ID`` cell, else by the SIS User ID or SIS Login ID, else by name.
  An empty cell or ``-`` is no score. Commas or semicolons separate the cells.
- **Moodle** (Grades > Import > CSV file) takes any header row: the teacher maps
  one column to the user field that identifies students (ID number, email,
  username or Moodle's user id) and another to a grade item (or a new one).
  An empty cell or ``-`` is no grade. A row whose identifying cell is empty
  is not skipped safely: its grade goes to the student of the row above, and
  a student Moodle does not know stops the whole import.

One file serves both: Canvas's header,
``Student,ID,SIS User ID,SIS Login ID,Section,<column>``, with the roster's id
under ``SIS User ID`` (or ``SIS Login ID``, `id_header`), Canvas's ``ID`` and
``Section`` empty, and no "Points Possible" row (Moodle would take it for a
student). In Moodle, map "SIS User ID" to the user field the roster's ids
are, and `<column>` to the grade item. Entries without an id are left out
(Moodle would give their grade to the row above); a student not graded has an empty
score cell (no grade; over a grade entered in the LMS it may clear it). UTF-8
without a byte-order mark, CRLF line ends, RFC 4180 quoting, cells made safe
for spreadsheets (harness.safe_text.for_csv).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable

from harness.errors import ConfigError
from harness.safe_text import clip, for_csv

__all__ = ["ID_HEADERS", "gradebook_csv"]

#: Where the roster's id goes: Canvas's SIS user id (student number) or SIS login id.
ID_HEADERS = ("SIS User ID", "SIS Login ID")
#: Canvas's student columns: an assignment column must not be called like one.
RESERVED = ("Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Integration ID")
#: Canvas skips every column whose header holds one of these (its computed columns).
COMPUTED = (
    "Current Score",
    "Current Points",
    "Current Grade",
    "Final Score",
    "Final Points",
    "Final Grade",
    "Override Score",
    "Override Grade",
    "Override Status",
)
CELL_LIMIT = 200


def _score_cell(score: float | None, max_score: float, who: str) -> str:
    """'7.5', '10', '0.33'; '' for no score. A score outside 0..max_score is a bug."""
    if score is None:
        return ""
    if not math.isfinite(score) or score < -1e-9 or score > max_score + 1e-9:
        raise ValueError(f"{who}: score {score!r} is not within 0..{max_score:g}")
    text = f"{round(max(0.0, min(score, max_score)), 2):.2f}".rstrip("0").rstrip(".")
    return text or "0"


def check_column(column: str) -> str:
    """The assignment column's header, checked; ConfigError (exit 2) says why not."""
    name = column.strip()
    if not name:
        raise ConfigError("the gradebook column must be named (the LMS's assignment title)")
    if not name.isprintable() or len(name) > CELL_LIMIT:
        raise ConfigError(f"gradebook column {clip(name, 60)!r}: one printable line, please")
    if name in RESERVED or any(c in name for c in COMPUTED):
        raise ConfigError(
            f"gradebook column {name!r}: Canvas reads that header as its own, not as an "
            "assignment; name it after the assignment"
        )
    return name


def gradebook_csv(
    entries: Iterable[tuple[str, str, float | None]],
    *,
    column: str,
    max_score: float,
    id_header: str = "SIS User ID",
) -> bytes:
    """The CSV for `entries`, (roster id, name, score or None when not graded), in the
    given order; `column` is the LMS assignment's title, `max_score` what it is out of.
    Entries with an empty id are left out (list them to the instructor yourself)."""
    name = check_column(column)
    if id_header not in ID_HEADERS:
        raise ValueError(f"id_header must be one of {', '.join(ID_HEADERS)}")
    if not math.isfinite(max_score) or max_score <= 0:
        raise ValueError(f"max_score must be a positive number, got {max_score!r}")
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    header = ["Student", "ID", *ID_HEADERS, "Section", name]
    writer.writerow([for_csv(cell) for cell in header])
    at = header.index(id_header)
    for student_id, student, score in entries:
        student_id = student_id.strip()
        if not student_id:
            continue
        row = ["", "", "", "", "", _score_cell(score, max_score, student_id)]
        row[0], row[at] = student.strip(), student_id
        writer.writerow([for_csv(clip(cell, CELL_LIMIT)) for cell in row])
    return buffer.getvalue().encode("utf-8")
