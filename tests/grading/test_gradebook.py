"""gradebook_csv: one file that Canvas's and Moodle's grade imports both read (pure).

The two importers are played here by what their code does with a CSV (Canvas's
app/models/gradebook_importer.rb, Moodle's grade/import/csv/classes/load_data.php):
Canvas's header rules and where it looks for a student's ids, Moodle's column
mapping, and both reading an empty cell as no grade.
"""

from __future__ import annotations

import csv
import io
import re

import pytest

from harness.errors import ConfigError
from harness.grading.gradebook import gradebook_csv

ENTRIES = [
    ("s1001", "Ana Lima", 7.5),
    ("s1002", "Doe, Jo", 10.0),
    ("s1003", '=HYPERLINK("x")', 1 / 3),
    ("", "no roster id", 5.0),  # left out: Moodle would give it to the row above
    ("s1004", "Bo", None),  # not graded
    ("s1005", "Zed", 0.0),
]


def rows(data: bytes, delimiter: str = ",") -> list[list[str]]:
    text = data.decode("utf-8")
    assert not text.startswith("\ufeff") and text.endswith("\r\n")
    return list(csv.reader(io.StringIO(text), delimiter=delimiter))


def canvas_reads(data: bytes) -> dict[str, dict[str, str | None]]:
    """What Canvas's importer takes from the file: per student (SIS user or login id, or
    name), each assignment column's grade (None: no score)."""
    header, *body = rows(data)
    # its header check: "Student" then "ID", more than 3 columns, Section last of the
    # student columns (after an optional SIS User ID + SIS Login ID pair)
    assert len(header) > 3 and "Student" in header[0] and "ID" in header[1]
    columns = 3
    if re.search(r"SIS\s+Login\s+ID", header[2]):
        sis_user, sis_login, columns = None, 2, 4
    elif re.search(r"SIS\s+User\s+ID", header[2]) and re.search(r"SIS\s+Login\s+ID", header[3]):
        sis_user, sis_login, columns = 2, 3, 5
    else:
        sis_user = sis_login = None
    assert "Section" in header[columns - 1]
    assignments = header[columns:]
    taken: dict[str, dict[str, str | None]] = {}
    for row in body:
        assert not row[0].startswith("Points Possible")
        assert not row[1], "Canvas's own user id: we never know it"
        who = (sis_user is not None and row[sis_user]) or (sis_login and row[sis_login]) or row[0]
        grades = [g.strip() for g in row[columns:]]
        taken[who] = {
            a: (g if g not in ("", "-") else None) for a, g in zip(assignments, grades, strict=True)
        }
    return taken


def moodle_reads(data: bytes, map_from: str, grade_item: str) -> dict[str, float | None]:
    """What Moodle's CSV import takes with `map_from` mapped to a user field and
    `grade_item` to a grade item: user value -> grade (None: no grade)."""
    header, *body = rows(data)
    ident, item = header.index(map_from), header.index(grade_item)
    taken: dict[str, float | None] = {}
    for row in body:
        if len(row) <= 1:
            continue
        user = row[ident].strip()
        assert user, "a row without its user would take the grade of the row above"
        value = row[item].strip()
        taken[user] = None if value in ("", "-") else float(value)
    return taken


def test_canvas_finds_each_student_by_sis_user_id_and_reads_the_assignment() -> None:
    data = gradebook_csv(ENTRIES, column="Lab 07: LIDAR node", max_score=10)
    assert rows(data)[0] == [
        "Student",
        "ID",
        "SIS User ID",
        "SIS Login ID",
        "Section",
        "Lab 07: LIDAR node",
    ]
    assert canvas_reads(data) == {
        "s1001": {"Lab 07: LIDAR node": "7.5"},
        "s1002": {"Lab 07: LIDAR node": "10"},
        "s1003": {"Lab 07: LIDAR node": "0.33"},
        "s1004": {"Lab 07: LIDAR node": None},
        "s1005": {"Lab 07: LIDAR node": "0"},
    }


def test_the_id_can_go_under_sis_login_id_instead() -> None:
    data = gradebook_csv(ENTRIES[:1], column="Lab 07", max_score=10, id_header="SIS Login ID")
    assert rows(data)[1] == ["Ana Lima", "", "", "s1001", "", "7.5"]
    assert canvas_reads(data) == {"s1001": {"Lab 07": "7.5"}}


def test_moodle_maps_the_id_column_to_a_user_field_and_the_score_to_a_grade_item() -> None:
    data = gradebook_csv(ENTRIES, column="Lab 07", max_score=10)
    assert moodle_reads(data, "SIS User ID", "Lab 07") == {
        "s1001": 7.5,
        "s1002": 10.0,
        "s1003": 0.33,
        "s1004": None,
        "s1005": 0.0,
    }


def test_cells_are_text_a_spreadsheet_never_runs() -> None:
    body = rows(gradebook_csv(ENTRIES, column="Lab 07", max_score=10))[1:]
    assert ["Doe, Jo", "", "s1002", "", "", "10"] in body  # the comma quoted, not a column
    formula = next(r for r in body if r[2] == "s1003")
    assert formula[0] == '\'=HYPERLINK("x")'
    assert all(not cell.startswith(("=", "+", "-", "@")) for row in body for cell in row)


def test_an_empty_class_is_a_header() -> None:
    assert len(rows(gradebook_csv([], column="Lab 07", max_score=10))) == 1


@pytest.mark.parametrize(
    ("column", "needle"),
    [
        ("", "must be named"),
        ("  ", "must be named"),
        ("Section", "Canvas reads that header as its own"),
        ("Final Score", "Canvas reads that header as its own"),
        ("Lab 07 Current Score", "Canvas reads that header as its own"),
        ("two\nlines", "one printable line"),
    ],
)
def test_a_column_an_lms_would_misread_is_a_usage_error(column: str, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle):
        gradebook_csv(ENTRIES, column=column, max_score=10)


@pytest.mark.parametrize("score", [-0.5, 10.5, float("nan"), float("inf")])
def test_a_score_outside_the_range_is_a_bug_not_a_grade(score: float) -> None:
    with pytest.raises(ValueError, match="s9"):
        gradebook_csv([("s9", "x", score)], column="Lab 07", max_score=10)


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError, match="max_score"):
        gradebook_csv(ENTRIES, column="Lab 07", max_score=0)
    with pytest.raises(ValueError, match="id_header"):
        gradebook_csv(ENTRIES, column="Lab 07", max_score=10, id_header="Email")
