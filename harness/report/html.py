"""index.html: the run on one page, readable offline and from a CI artifact.

Built from summary.json's data, so the page and the file cannot disagree;
no scripts. All text is escaped (safe_text): names, statuses and a node's
output come from users and students.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from html import escape
from typing import Any
from urllib.parse import quote

from harness.judge.reading_coverage import CASE_NAMES, other_counts
from harness.option_names import worded
from harness.report.summary import passed_line
from harness.safe_text import DIAGNOSTICS_LIMIT, TEXT_LIMIT, clip, for_html, visible

__all__ = ["index_html"]

DIAGNOSTIC_LINES = 15
CHANGE_HEAD = ["change", "scenario", "faults", "then", "now", "why"]

_STYLE = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em auto; max-width: 72em; color: #222; }
table { border-collapse: collapse; }
th, td { padding: 0.2em 0.5em; text-align: left; border-bottom: 1px solid #ddd; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
td.faults { overflow-wrap: anywhere; min-width: 8em; }
td.faults span { display: inline-block; }
.PASS { color: #1a7f37; font-weight: bold; }
.FAIL, .ERROR { color: #c62828; font-weight: bold; }
.NOT_RUN { color: #9a6700; font-weight: bold; }
.regressed { color: #c62828; font-weight: bold; }
.fixed { color: #1a7f37; font-weight: bold; }
.still_failing, .new, .not_compared, .missing, p.note { color: #9a6700; }
p.failure { color: #c62828; font-family: monospace; white-space: pre-wrap; }
p.misaligned { color: #9a6700; font-weight: bold; }
p.misaligned.fails { color: #c62828; }
pre { background: #f6f6f6; padding: 0.5em; overflow-x: auto; }
img { max-width: 100%; border: 1px solid #ddd; }
"""


def _text(value: object, limit: int = TEXT_LIMIT) -> str:
    return for_html(clip(str(value), limit))


def _href(path: str) -> str:
    return escape(quote(path), quote=True)


def _word(word: str) -> str:
    """A verdict or a change, styled by its own class."""
    return f'<span class="{word.replace(" ", "_")}">{_text(word)}</span>'


def _faults(faults: str) -> str:
    """Fault names joined by "+", each in a box of its own: a line breaks after a "+"
    (and inside a name only when the name alone is wider than the column)."""
    return "<span>" + "+</span><span>".join(_text(faults).split("+")) + "</span>"


def _file_links(files: Mapping[str, str | None]) -> str:
    return " ".join(f'<a href="{_href(p)}">{_text(n)}</a>' for n, p in files.items() if p)


def _row(i: int, e: Mapping[str, Any]) -> str:
    change = [_word(e["change"])] if "change" in e else []
    cells = [
        f'<a href="#scenario-{i}">{_text(e["scenario"])}</a>',
        _text(e["link"]),
        f'<td class="n">{e["ticks"]}',
        f'<td class="n">{e["failed"]}',
        _word(e["verdict"]),
        *change,
        f'<td class="n">{e["total_s"]:.2f}',
        f'<td class="n">{_text(e["seed"])}',
        f'<td class="n">{_text(e["threshold"])}',
        _text(e.get("warning_when_clear", "optional")),
        f'<td class="faults">{_faults(e["faults"])}',
        _file_links(e["files"]),
    ]
    return "<tr>" + "".join(c if c.startswith("<td") else f"<td>{c}" for c in cells) + "</tr>"


def _section(i: int, e: Mapping[str, Any], diagnostics: str) -> list[str]:
    out = [f'<h2 id="scenario-{i}">{_text(e["scenario"])} {_word(e["verdict"])}</h2>']
    detail = f"{e['ticks']} ticks, {e['failed']} failed; link {e['link']}, seed {e['seed']}"
    out.append(f"<p>{_text(detail)}. {_file_links(e['files'])}</p>")
    if e["first_failure"]:
        out.append(f'<p class="failure">{_text(e["first_failure"])}</p>')
    error = e["error"]
    if error and error not in (e["first_failure"] or ""):
        out.append(f'<p class="failure">run ended: {_text(error)}</p>')
    if diagnostics and not e["ok"]:
        lines = visible(clip(diagnostics, DIAGNOSTICS_LIMIT)).rstrip().split("\n")
        tail = "\n".join(lines[-DIAGNOSTIC_LINES:])
        out.append(f"<pre>{_text(tail, DIAGNOSTICS_LIMIT)}</pre>")
    files = e["files"]
    if files.get("plot"):
        alt = f"plot of {e['scenario']}: ranges, the node's answers and failed ticks over time"
        out.append(_image(files["plot"], alt))
    if files.get("animation"):
        alt = f"animation of {e['scenario']}: the robot from above, its scan and the node's answers"
        out.append(_image(files["animation"], alt))
    return out


def _image(path: str, alt: str) -> str:
    """An image that links to itself (loaded when scrolled to: a run may have many)."""
    href = _href(path)
    return f'<p><a href="{href}"><img src="{href}" alt="{_text(alt)}" loading="lazy"></a></p>'


def _alignment(alignment: Mapping[str, Any]) -> list[str]:
    """The board's /scan against the truth (serial links): turned, mirrored, or as shown."""
    kind = _text(alignment["status"])
    fails = " fails" if alignment["fails_run"] else ""
    lead = ""
    if alignment["status"] == "misaligned":
        lead = worded("FAILED ({alignment} fail): ") if fails else "WARNING: "
    return [
        "<h2>Alignment of the board's /scan</h2>",
        f'<p class="{kind}{fails}">{_text(lead + alignment["text"])}</p>',
    ]


def _baseline(comparison: Mapping[str, Any]) -> list[str]:
    """The comparison with `--baseline`: notes, every change but "still passing", counts."""
    out = [
        "<h2>Compared with the baseline</h2>",
        f"<p>{_text(comparison['file'])} (fossbot-hil {_text(comparison['harness'])})</p>",
        *(f'<p class="note">note: {_text(note)}</p>' for note in comparison["notes"]),
    ]
    rows = [c for c in comparison["changes"] if c["change"] != "still passing"]
    if rows:
        out.append("<table>")
        out.append("<tr>" + "".join(f"<th>{h}" for h in CHANGE_HEAD) + "</tr>")
        for c in rows:
            cells = [c["scenario"], c["faults"], c["then"] or "-", c["now"] or "-"]
            out.append(
                f"<tr><td>{_word(c['change'])}"
                + "".join(f"<td>{_text(x)}" for x in cells)
                + f"<td>{_text(c['reason'] or '')}</tr>"
            )
        out.append("</table>")
    counts = ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in comparison["counts"].items() if n)
    verdict = "no regression" if comparison["ok"] else "failing, and not known from the baseline"
    out.append(f"<p>{_text(counts)}: <strong>{_text(verdict)}</strong>.</p>")
    return out


def _coverage(coverage: Mapping[str, Any]) -> list[str]:
    """The readings the delivered scans carried (harness.judge.reading_coverage), and gaps."""
    total = coverage["total"]
    out = [
        "<h2>Readings the suite delivered</h2>",
        f"<p>Scans the node received, {total['scans']} in all, that hold each kind of reading:</p>",
        "<table>",
        "<tr><th>reading<th>beside a valid return<th>without one</tr>",
    ]
    for case, n in total["cases"].items():
        out.append(
            f"<tr><td>{_text(CASE_NAMES.get(case, case))}"
            f'<td class="n">{n["beside_valid"]}<td class="n">{n["without_valid"]}</tr>'
        )
    out.extend(
        f'<tr><td>{_text(what)}<td class="n" colspan="2">{n}</tr>'
        for what, n in other_counts(total)
    )
    out.append("</table>")
    if coverage["gaps"]:
        out.append("<p>What the suite never delivered:</p>")
        out.append('<p class="note">' + "<br>".join(_text(g) for g in coverage["gaps"]) + "</p>")
    else:
        out.append("<p>The suite delivered every kind of reading above.</p>")
    return out


def index_html(summary: Mapping[str, Any], *, diagnostics: Sequence[str] = ()) -> bytes:
    """The page for a run summary (see harness.report.summary.run_summary), with the
    comparison harness.report.baseline.with_comparison added, when there is one, the
    alignment of the board's /scan, when it has one, and the readings delivered."""
    entries = summary["scenarios"]
    headline = passed_line(summary["passed"], summary["total"])
    head = ["scenario", "link", "ticks", "failed", "verdict", "time s", "seed", "threshold"]
    head.append("warning when clear")  # "optional", or "required" (--warning-when-clear)
    if "baseline" in summary:
        head.insert(5, "vs baseline")
    lines = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        '<head><meta charset="utf-8">',
        f"<title>fossbot-hil: {_text(headline)}</title>",
        f"<style>{_STYLE}</style></head>",
        "<body>",
        f"<h1>fossbot-hil: {_text(headline)}</h1>",
        '<p>Machine-readable: <a href="summary.json">summary.json</a>, '
        '<a href="junit.xml">junit.xml</a>.</p>',
        "<table>",
        "<tr>" + "".join(f"<th>{h}" for h in [*head, "faults", "files"]) + "</tr>",
        *(_row(i, e) for i, e in enumerate(entries)),
        "</table>",
    ]
    lines.extend(f'<p class="note">note: {_text(note)}</p>' for note in summary.get("notes", ()))
    if summary.get("alignment"):
        lines.extend(_alignment(summary["alignment"]))
    if "baseline" in summary:
        lines.extend(_baseline(summary["baseline"]))
    if summary.get("coverage"):
        lines.extend(_coverage(summary["coverage"]))
    for i, e in enumerate(entries):
        lines.extend(_section(i, e, diagnostics[i] if i < len(diagnostics) else ""))
    lines += ["</body>", "</html>", ""]
    return "\n".join(lines).encode()
