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
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from urllib.parse import quote

from rich.table import Table
from rich.text import Text

from harness.safe_text import TEXT_LIMIT, clip, for_csv, for_html, for_terminal

__all__ = ["StudentGrade", "class_csv", "class_html", "class_rich_table", "scenario_legend"]

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
    ticks: dict[str, tuple[int, int]] = field(default_factory=dict)  # (held, judged)
    node: str = ""  # the node the suite ran, e.g. "lidar_node.py (script)"
    failures: dict[str, str] = field(default_factory=dict)  # scenario -> its first failure
    notes: tuple[str, ...] = ()  # said once about the whole run, e.g. a launch file's problem
    points: float | None = None  # the score (harness.grading.scoring); None: not scored
    student_id: str = ""  # from the roster
    full_name: str = ""  # from the roster

    @property
    def passed(self) -> int:
        return sum(1 for v in self.verdicts.values() if v == PASS)

    @property
    def score(self) -> str:
        return f"{self.passed}/{len(self.verdicts)}"

    def scenario_ticks(self, scenario: str) -> str:
        """'88/95': the ticks of `scenario` whose expectations held, of those it should have
        run (a scenario that broke early counts its missing ticks as not held)."""
        if scenario not in self.ticks:
            return ""
        held, judged = self.ticks[scenario]
        return f"{held}/{judged}"

    @property
    def ticks_held(self) -> str:
        """The partial score over the suite: '480/544 (88%)'."""
        held = sum(h for h, _ in self.ticks.values())
        judged = sum(j for _, j in self.ticks.values())
        return f"{held}/{judged} ({100 * held // judged}%)" if judged else ""


def _cell(text: str) -> str:
    """A CSV cell a spreadsheet shows as text, never runs as a formula."""
    return for_csv(clip(text, TEXT_LIMIT))


def points_cell(grade: StudentGrade) -> str:
    """The score as a table shows it: '7.5', or '' when not scored."""
    return "" if grade.points is None else f"{round(grade.points, 2):g}"


def class_csv(
    grades: Sequence[StudentGrade], scenarios: Sequence[str], *, roster: bool = False
) -> bytes:
    """student, (id, name with a roster,) node, per scenario its verdict and ticks held,
    passed, ticks_held, score, first_failure, notes (UTF-8, RFC 4180 quoting)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\r\n")
    per_scenario = [c for s in scenarios for c in (s, f"{s} ticks")]
    who = ["student", "id", "name"] if roster else ["student"]
    writer.writerow(
        [*who, "node", *per_scenario, "passed", "ticks_held", "score", "first_failure", "notes"]
    )
    for g in grades:
        cells = [c for s in scenarios for c in (g.verdicts.get(s, NOT_RUN), g.scenario_ticks(s))]
        names = [g.name, g.student_id, g.full_name] if roster else [g.name]
        row = [*names, g.node, *cells, g.score, g.ticks_held, points_cell(g), g.first_failure]
        row.append(" | ".join(g.notes))
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
th.scenario span { display: inline-block; }
td.student { overflow-wrap: anywhere; }
p.audit { margin: 0 0 1em; padding: .4em .6em; background: #fdf5d8; color: #5c4500; }
td.student { min-width: 9em; }
td.why { min-width: 12em; }
td.student small { color: #555; }
td.student a { color: #555; }
td.v small { font-weight: normal; color: #555; }
@media print { body { margin: 0; font-size: 10px; } a { text-decoration: none; } }
"""


def _h(text: object) -> str:
    return for_html(clip(str(text), TEXT_LIMIT))


def _t(text: str, style: str = "") -> Text:
    return Text(for_terminal(clip(text, TEXT_LIMIT)), style=style)


def _breakable(name: str) -> str:
    """A scenario's name, escaped, that a narrow column breaks only after an underscore,
    a hyphen or a dot ("approach_" / "wall"), never inside a word: each piece is an
    inline block (a line may break between two, not inside one)."""
    pieces = re.findall(r"[^_.-]*[_.-]|[^_.-]+$", clip(name, TEXT_LIMIT)) or [""]
    return "".join(f"<span>{for_html(piece)}</span>" for piece in pieces)


def _verdict_cell(grade: StudentGrade, scenario: str) -> str:
    verdict = grade.verdicts.get(scenario, NOT_RUN)
    ticks = grade.scenario_ticks(scenario)
    held = f"<br><small>{_h(ticks)}</small>" if ticks else ""
    return f'<td class="v {_h(verdict.replace(" ", "-"))}">{_h(verdict)}{held}</td>'


def _notes_html(grade: StudentGrade) -> str:
    """What the run said about how the node is wired (e.g. its launch file), under the
    first failure."""
    return "".join(f"<br><small>note: {_h(n)}</small>" for n in grade.notes)


def class_html(
    grades: Sequence[StudentGrade],
    scenarios: Sequence[str],
    *,
    title: str = "FOSSBot LIDAR lab: class results",
    meta: Sequence[tuple[str, str]] = (),
    max_score: float | None = None,
    audit: str | None = None,
) -> bytes:
    """One self-contained page (inline CSS, no script); every text escaped. `audit` is
    grade's line about the scenarios' audit (which typical mistakes they let pass, or what
    the audit could not run), shown above the table."""
    passed_all = sum(1 for g in grades if g.passed == len(scenarios) and scenarios)
    about = [f"{len(grades)} students, {passed_all} passed every scenario", *map(": ".join, meta)]
    head = "".join(f'<th class="scenario">{_breakable(s)}</th>' for s in scenarios)
    rows = []
    for g in grades:
        links = " · ".join(
            f'<a href="{_h(quote(path))}">{_h(label)}</a>' for label, path in g.artifacts
        )
        cells = "".join(_verdict_cell(g, s) for s in scenarios)
        node = g.node or g.kind
        who = " · ".join(_h(x) for x in (g.student_id, g.full_name) if x)
        who = f"<br><small>{who}</small>" if who else ""
        rows.append(
            f'<tr><td class="student">{_h(g.name)}{who}<br><small>{_h(node)}'
            f"{' · ' + links if links else ''}</small></td>{cells}"
            f'<td class="v">{_h(g.score)}<br><small>{_h(g.ticks_held)}</small></td>'
            f'<td class="v">{_h(points_cell(g))}</td>'
            f'<td class="why">{_h(g.first_failure)}{_notes_html(g)}</td></tr>'
        )
    page = (
        "<!DOCTYPE html>\n"
        f'<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{_h(title)}</title>\n'
        f"<style>{_CSS}</style>\n</head>\n<body>\n<h1>{_h(title)}</h1>\n"
        f'<p class="meta">{" · ".join(_h(a) for a in about)}</p>\n'
        + (f'<p class="audit">{_h(audit)}</p>\n' if audit else "")
        + f"<table>\n<thead><tr><th>student</th>{head}<th>passed<br><small>ticks held</small></th>"
        f"<th>score{'<br><small>of ' + _h(f'{max_score:g}') + '</small>' if max_score else ''}"
        "</th><th>first failure</th></tr>"
        "</thead>\n<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>\n</body>\n</html>\n"
    )
    return page.encode("utf-8")


LETTERS = {PASS: "P", FAIL: "F", ERROR: "E", NOT_RUN: "-"}
MAX_NAME = 20  # a student's name in the terminal table
MIN_FAILURE = 20  # the first failure's least width there


def class_rich_table(
    grades: Sequence[StudentGrade], scenarios: Sequence[str], width: int = 100
) -> Table:
    """The same rows, one line each on a terminal `width` columns wide: a letter per
    scenario (numbered as in `scenario_legend`), the partial score, and the first failure
    cut to what is left of the line (the whole of it is in grades.html and the CSV)."""
    names = min(MAX_NAME, max([len("student"), *(len(g.name) for g in grades)]))
    passed = max([len("passed"), *(len(g.score) for g in grades)])
    held = max([len("ticks held"), *(len(g.ticks_held) for g in grades)])
    scored = max([len("score"), *(len(points_cell(g)) for g in grades)])
    numbers = sum(len(str(i)) for i in range(1, len(scenarios) + 1))
    gaps = 2 * (len(scenarios) + 4)  # two spaces between columns
    room = max(MIN_FAILURE, width - names - numbers - passed - held - scored - gaps)
    table = Table(box=None, pad_edge=False)
    table.add_column("student", no_wrap=True, overflow="ellipsis", max_width=MAX_NAME)
    for number in range(1, len(scenarios) + 1):
        table.add_column(str(number), justify="center", no_wrap=True)
    table.add_column("passed", justify="right", no_wrap=True)
    table.add_column("ticks held", justify="right", no_wrap=True)
    table.add_column("score", justify="right", no_wrap=True)
    table.add_column("first failure", no_wrap=True, overflow="ellipsis", max_width=room)
    for g in grades:
        verdicts = [g.verdicts.get(s, NOT_RUN) for s in scenarios]
        cells = [_t(LETTERS.get(v, "?"), VERDICT_STYLE.get(v, "")) for v in verdicts]
        table.add_row(
            _t(g.name), *cells, g.score, g.ticks_held, points_cell(g), _t(g.first_failure)
        )
    return table


def scenario_legend(scenarios: Sequence[str]) -> str:
    """What the terminal table's numbered columns and letters mean."""
    numbered = ", ".join(f"{i} {s}" for i, s in enumerate(scenarios, 1))
    return f"scenarios: {numbered}; P pass, F fail, E error, - not run"
