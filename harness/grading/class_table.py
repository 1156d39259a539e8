"""The class table: one row per student, one verdict column per scenario, the first failure.

Rendered three ways from the same rows: CSV (for a spreadsheet), one HTML
page (to read or print), and a rich table for the terminal. Pure: no file
writing here (``grade`` writes these bytes atomically), no rclpy, no pybullet.
Student names and failures come from students: every text is bounded and
made safe for its medium by harness.safe_text.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from urllib.parse import quote

from rich.table import Table
from rich.text import Text

from harness.safe_text import TEXT_LIMIT, clip, for_csv, for_html, for_terminal

__all__ = ["StudentGrade", "class_csv", "class_html", "class_rich_table"]

PASS, FAIL, ERROR, NOT_RUN = "PASS", "FAIL", "ERROR", "NOT RUN"
VERDICT_STYLE = {PASS: "green", FAIL: "red", ERROR: "red", NOT_RUN: "yellow"}


@dataclass(frozen=True)
class StudentGrade:
    """One row: a student's verdict per scenario and the failure to read first."""

    name: str
    kind: str  # workspace, package, script, none
    verdicts: dict[str, str]  # scenario -> PASS / FAIL / ERROR / NOT RUN, in suite order
    first_failure: str = ""  # "" when every scenario passed
    artifacts: tuple[tuple[str, str], ...] = ()  # (label, path relative to the table)
    build_s: float | None = None  # None: nothing was built (a script, or no node)
    run_s: float | None = None

    @property
    def passed(self) -> int:
        return sum(1 for v in self.verdicts.values() if v == PASS)

    @property
    def score(self) -> str:
        return f"{self.passed}/{len(self.verdicts)}"


def _cell(text: str) -> str:
    """A CSV cell a spreadsheet shows as text, never runs as a formula."""
    return for_csv(clip(text, TEXT_LIMIT))


def class_csv(grades: Sequence[StudentGrade], scenarios: Sequence[str]) -> bytes:
    """student, one column per scenario, passed, first_failure (UTF-8, RFC 4180 quoting)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    writer.writerow(["student", *scenarios, "passed", "first_failure"])
    for g in grades:
        row = [g.name, *(g.verdicts.get(s, NOT_RUN) for s in scenarios), g.score, g.first_failure]
        writer.writerow([_cell(c) for c in row])
    return buffer.getvalue().encode("utf-8")


_CSS = """
body { font: 13px/1.35 system-ui, sans-serif; margin: 1.5em; color: #111; }
h1 { font-size: 1.3em; margin: 0 0 .3em; }
p.meta { color: #555; margin: 0 0 1em; }
table { border-collapse: collapse; width: 100%; }
th, td { border: 1px solid #ccc; padding: .25em .45em; vertical-align: top; text-align: left; }
th { background: #f2f2f2; }
td.v { white-space: nowrap; text-align: center; font-weight: 600; }
td.PASS { background: #e3f5e1; color: #17621a; }
td.FAIL, td.ERROR { background: #fbe3e1; color: #9b1c12; }
td.NOT-RUN { background: #fdf5d8; color: #7a5c00; }
td.why { font-size: .92em; word-break: break-word; }
td.student small { color: #555; }
td.student a { color: #555; }
@media print { body { margin: 0; font-size: 10px; } a { text-decoration: none; } }
"""


def _h(text: object) -> str:
    return for_html(clip(str(text), TEXT_LIMIT))


def _t(text: str, style: str = "") -> Text:
    return Text(for_terminal(clip(text, TEXT_LIMIT)), style=style)


def class_html(
    grades: Sequence[StudentGrade],
    scenarios: Sequence[str],
    *,
    title: str = "FOSSBot LIDAR lab: class results",
    meta: Sequence[tuple[str, str]] = (),
) -> bytes:
    """One self-contained page (inline CSS, no script); every text escaped."""
    passed_all = sum(1 for g in grades if g.passed == len(scenarios) and scenarios)
    about = [f"{len(grades)} students, {passed_all} passed every scenario", *map(": ".join, meta)]
    head = "".join(f"<th>{_h(s)}</th>" for s in scenarios)
    rows = []
    for g in grades:
        links = " · ".join(
            f'<a href="{_h(quote(path))}">{_h(label)}</a>' for label, path in g.artifacts
        )
        cells = "".join(
            f'<td class="v {_h(v.replace(" ", "-"))}">{_h(v)}</td>'
            for v in (g.verdicts.get(s, NOT_RUN) for s in scenarios)
        )
        rows.append(
            f'<tr><td class="student">{_h(g.name)}<br><small>{_h(g.kind)}'
            f"{' · ' + links if links else ''}</small></td>{cells}"
            f'<td class="v">{_h(g.score)}</td><td class="why">{_h(g.first_failure)}</td></tr>'
        )
    page = (
        "<!DOCTYPE html>\n"
        f'<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{_h(title)}</title>\n'
        f"<style>{_CSS}</style>\n</head>\n<body>\n<h1>{_h(title)}</h1>\n"
        f'<p class="meta">{" · ".join(_h(a) for a in about)}</p>\n'
        f"<table>\n<thead><tr><th>student</th>{head}<th>passed</th><th>first failure</th></tr>"
        "</thead>\n<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>\n</body>\n</html>\n"
    )
    return page.encode("utf-8")


def class_rich_table(grades: Sequence[StudentGrade], scenarios: Sequence[str]) -> Table:
    """The same rows for the terminal, verdicts coloured, the failure folded to fit."""
    table = Table(box=None, pad_edge=False)
    table.add_column("student", overflow="fold")
    for s in scenarios:
        table.add_column(_t(s), overflow="fold")
    table.add_column("passed", justify="right")
    table.add_column("first failure", overflow="fold", ratio=1)
    for g in grades:
        verdicts = [g.verdicts.get(s, NOT_RUN) for s in scenarios]
        cells = [_t(v, VERDICT_STYLE.get(v, "")) for v in verdicts]
        table.add_row(_t(g.name), *cells, g.score, _t(g.first_failure))
    return table
