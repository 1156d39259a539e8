"""The class table as CSV and HTML: same rows, safe with any text a student can produce."""

from __future__ import annotations

import csv
import io
from html.parser import HTMLParser

from rich.console import Console

from harness.grading.class_table import (
    StudentGrade,
    class_csv,
    class_html,
    class_rich_table,
    scenario_legend,
)

SCENARIOS = ("approach_wall", "out_of_range")
NASTY = "<script>alert('x')</script> & \"quoted\""


def grades() -> list[StudentGrade]:
    return [
        StudentGrade("ana", "workspace", {"approach_wall": "PASS", "out_of_range": "PASS"}),
        StudentGrade(
            '=HYPERLINK("http://x")',
            "package",
            {"approach_wall": "FAIL", "out_of_range": "NOT RUN"},
            f"approach_wall: status {NASTY}",
            (("build log", "students/a b/build.log"),),
            ticks={"approach_wall": (30, 95)},
        ),
    ]


def test_csv_has_one_row_per_student_and_never_a_formula() -> None:
    """Header, verdicts, score, failure; a cell starting with '=' is quoted as text."""
    rows = list(csv.reader(io.StringIO(class_csv(grades(), SCENARIOS).decode("utf-8"))))
    assert rows[0] == [
        "student",
        "node",
        "approach_wall",
        "approach_wall ticks",
        "out_of_range",
        "out_of_range ticks",
        "passed",
        "ticks_held",
        "score",
        "first_failure",
        "notes",
    ]
    assert rows[1] == ["ana", "", "PASS", "", "PASS", "", "2/2", "", "", "", ""]
    assert rows[2] == [
        '\'=HYPERLINK("http://x")',
        "",
        "FAIL",
        "30/95",
        "NOT RUN",
        "",
        "0/2",
        "30/95 (31%)",
        "",
        f"approach_wall: status {NASTY}",
        "",
    ]


class _Collect(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.text: list[str] = []
        self.hrefs: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.hrefs += [v or "" for k, v in attrs if k == "href"]

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def test_html_escapes_everything_and_links_the_artifacts() -> None:
    """A student's text can never become markup; links are URL-quoted."""
    page = class_html(grades(), SCENARIOS, meta=[("seed", "7 <b>")]).decode("utf-8")
    parsed = _Collect()
    parsed.feed(page)
    assert "script" not in parsed.tags and "b" not in parsed.tags
    text = "".join(parsed.text)
    assert f"approach_wall: status {NASTY}" in text and "seed: 7 <b>" in text
    assert parsed.hrefs == ["students/a%20b/build.log"]
    assert parsed.tags.count("tr") == 3
    assert "1 passed every scenario" in text


def test_terminal_table_prints_text_verbatim() -> None:
    """Square brackets in a status are not taken for rich markup."""
    console = Console(width=300, record=True, color_system=None)
    rows = [StudentGrade("[bold]x", "script", {"approach_wall": "PASS"}, "status '[1.0]'")]
    console.print(class_rich_table(rows, ("approach_wall",)))
    out = console.export_text()
    assert "[bold]x" in out and "status '[1.0]'" in out and "1/1" in out


def test_terminal_table_fits_100_columns_with_the_failure_shortened() -> None:
    """Seven scenarios and a long failure: one line per student at 100 columns."""
    scenarios = [f"scenario_number_{i}" for i in range(7)]
    long = "approach_wall: t=1.20 s tick 12: " + "expected warning True; got False; " * 6
    rows = [
        StudentGrade(
            f"student_{i:02d}",
            "script",
            dict.fromkeys(scenarios, "FAIL"),
            long,
            ticks=dict.fromkeys(scenarios, (80, 95)),
        )
        for i in range(3)
    ]
    console = Console(width=100, record=True, color_system=None)
    console.print(class_rich_table(rows, scenarios))
    lines = console.export_text().rstrip("\n").split("\n")
    assert len(lines) == 1 + len(rows), lines  # a header, then one line per student
    assert all(len(line) <= 100 for line in lines)
    assert "560/665 (84%)" in lines[1] and lines[1].endswith("…")
    legend = scenario_legend(scenarios)
    assert legend.startswith("scenarios: 1 scenario_number_0, 2 scenario_number_1")
