"""Text from the node under test cannot break a report, drive a terminal or bloat a file.

Real runs (a hostile ROS 2 node, a student graded, a processing function
answering a megabyte a tick) and a property test over arbitrary text: every
JUnit file parses as XML 1.0, every JSON file parses, the HTML holds no raw
control character or markup from the node, the terminal output no escape
sequence, and everything stays small however long the node's texts are.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import shutil
import subprocess
import sys
import xml.dom.minidom
import xml.etree.ElementTree as ET
import xml.sax
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from command_line import COMMAND, fossbot_hil
from deadlines import GENEROUS_READY_S, GENEROUS_S
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from property_depth import examples
from rich.console import Console

from harness.cli import _print_error
from harness.grading.class_table import StudentGrade, class_csv, class_html, class_rich_table
from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.lidar.scan import Scan
from harness.pytest_plugin.result import HilResult
from harness.report.html import index_html
from harness.report.junit import junit_xml
from harness.report.outputs import stored
from harness.report.summary import json_bytes, run_summary, scenario_details, scenario_entry
from harness.report.terminal import print_results
from harness.safe_text import TEXT_LIMIT

ROS_TESTS = Path(__file__).parents[1] / "ros"
HOSTILE = ROS_TESTS / "hostile_node.py"
WALL = ROS_TESTS / "hostile_wall.yaml"  # 21 ticks, a wall 0.4 m ahead
# What a node must never get through to a terminal, an XML file or a page.
POISON = ("\x1b", "\x00", "\x07", "\r", "\u202e", "\x9b", "\x0b", "\x0c")
HTML_TAGS = {"html", "head", "meta", "title", "style", "body", "h1", "h2", "p", "a", "table"}
HTML_TAGS |= {"tr", "th", "td", "span", "pre", "img", "thead", "tbody", "br", "small"}


def raw_controls(text: str) -> list[str]:
    """The characters of `text` that are not printable, other than newline and tab."""
    return sorted({c for c in text if not c.isprintable() and c not in "\n\t"})


def assert_xml_valid(data: bytes) -> None:
    """Three parsers, the strict ones included, read the JUnit file."""
    ET.fromstring(data)
    xml.dom.minidom.parseString(data)
    xml.sax.parseString(data, xml.sax.ContentHandler())


class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.add(tag)


def assert_html_safe(page: str) -> None:
    """No raw control character, and no tag but the page's own (input's `<` is escaped)."""
    assert raw_controls(page) == []
    parser = _Tags()
    parser.feed(page)
    assert parser.tags <= HTML_TAGS, parser.tags - HTML_TAGS


# -- a hostile ROS 2 node, through the command line ---------------------------


@pytest.mark.ros
@pytest.mark.timeout(90)
def test_a_node_writing_control_characters_gets_safe_reports(tmp_path: Path) -> None:
    """ESC, NUL, BEL, CR, U+202E and invalid UTF-8 on stderr, in the status and the error."""
    out, junit = tmp_path / "report", tmp_path / "ci.xml"
    node = f"{sys.executable} {HOSTILE} control_characters"
    done = fossbot_hil(
        "run",
        str(WALL),
        "--timeout",
        f"{GENEROUS_S:g}",  # it answers until it exits: no deadline is waited out
        "--ready-timeout",
        f"{GENEROUS_READY_S:g}",  # it comes up: not waited out
        "--node",
        node,
        "--out",
        str(out),
        "--junit-xml",
        str(junit),
        timeout=60,
    )
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert raw_controls(done.stdout + done.stderr) == []
    assert "\\x1b[J\\x1bc\\x07" in done.stdout  # shown, as escapes: the status
    assert "hostile \\x1b[J" in done.stdout  # and the node's stderr
    for path in (junit, out / "junit.xml"):
        assert_xml_valid(path.read_bytes())
    case = ET.parse(junit).find(".//testcase")
    assert case is not None and case.find("failure") is not None
    assert "\\u202e" in (case.find("failure").text or "")  # type: ignore[union-attr]
    page = (out / "index.html").read_text(encoding="utf-8")
    assert_html_safe(page)
    assert "[bold]x[/]" in page and "\\x1b[J" in page
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    details = json.loads((out / summary["scenarios"][0]["files"]["summary"]).read_text())
    assert details["records"][0]["status"].startswith("none \x1b[J\x1bc")  # kept exact
    assert "\ufffd" in details["diagnostics"]  # invalid UTF-8, replaced


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(120)
def test_grading_a_student_writing_control_characters_gives_safe_tables(tmp_path: Path) -> None:
    """`fossbot-hil grade`: the student's junit.xml, grades.csv and grades.html are safe."""
    student = tmp_path / "class" / "mallory"
    student.mkdir(parents=True)
    (student / "lib").mkdir()
    shutil.copy(HOSTILE, student / "lib" / "hostile_node.py")  # in the hand-in, as a sandbox
    # shows only the hand-in
    (student / "lidar_node.py").write_text(
        "import os\nimport runpy\nimport sys\n\n"
        'sys.argv[1:1] = ["control_characters"]\n'
        'runpy.run_path(os.path.join(os.path.dirname(__file__), "lib", "hostile_node.py"), '
        'run_name="__main__")\n'
    )
    out = tmp_path / "grades"
    done = subprocess.run(
        [
            *COMMAND,
            "grade",
            str(tmp_path / "class"),
            "--out",
            str(out),
            "--scenario",
            str(WALL),
            "--no-audit",
        ],
        capture_output=True,
        text=True,
        timeout=100,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert raw_controls(done.stdout + done.stderr) == []
    assert_xml_valid((out / "students" / "mallory" / "junit.xml").read_bytes())
    page = (out / "grades.html").read_text(encoding="utf-8")
    assert_html_safe(page)
    table = (out / "grades.csv").read_text(encoding="utf-8")
    assert raw_controls(table.replace("\r\n", "\n")) == []
    assert "\\x1b[J" in table and "\\x1b[J" in page  # the failure is there, shown safely


# -- arbitrary text, every writer -----------------------------------------------

NASTY = "\x1b\x00\x07\r\n\t\x0b\x0c\x7f\x85\x9b\u2028\u2029\u202e\u200f\ufeff\ufffe\ud800\udfff"
TEXTS = st.one_of(
    st.text(st.characters(exclude_categories=())),  # surrogates and controls included
    st.lists(st.sampled_from([*NASTY, *"<>&\"'é", "[bold]", "[/]", " 0.4 m"])).map("".join),
    st.binary().map(lambda b: b.decode("utf-8", "surrogateescape")),
    st.binary().map(lambda b: b.decode("utf-8", "replace")),
)
LONG_TEXTS = st.tuples(TEXTS, st.sampled_from([1, 1, 100, 20_000])).map(lambda t: t[0] * t[1])
SCAN = Scan(
    angle_min=-np.pi,
    angle_max=np.pi,
    angle_increment=2 * np.pi / 360,
    time_increment=0.1 / 360,
    scan_time=0.1,
    range_min=0.12,
    range_max=12.0,
    ranges=np.full(360, 0.4, dtype=np.float32),
)


def _result(status: str, diagnostics: str, error: str, scenario: str) -> RunResult:
    """One judged tick, recorded as the runner records it, and the run's texts as given."""
    answers = Answers(statuses=[Received(status, 0.01), Received(status[:9], 0.02)], waited=0.02)
    verdict = Oracle(0.5).judge(0, 0.0, SCAN, answers)
    record = TickRecord(0, 0.0, 0.0, 0.0, 0.0, SCAN, answers.clipped(), verdict.clipped())
    return RunResult(
        scenario, "ros2", 7, 0.5, "clean", records=[record], error=error, diagnostics=diagnostics
    )


@settings(max_examples=examples(120), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(status=LONG_TEXTS, diagnostics=LONG_TEXTS, error=LONG_TEXTS, scenario=TEXTS)
def test_any_text_makes_valid_bounded_reports(
    status: str, diagnostics: str, error: str, scenario: str
) -> None:
    """JUnit parses, JSON parses, HTML and terminal hold no control character; all bounded."""
    result = _result(status, diagnostics, error, scenario)
    limit = 40 * TEXT_LIMIT * 10  # a few texts of TEXT_LIMIT characters, each escaped
    xml_bytes = junit_xml([result])
    assert_xml_valid(xml_bytes)
    assert len(xml_bytes) < limit
    kept = stored(result)
    details = json_bytes(scenario_details(kept, {}))
    json.loads(details)
    summary = run_summary([scenario_entry(kept, {})])
    json.loads(json_bytes(summary))
    assert len(details) < limit
    page = index_html(summary, diagnostics=[kept.diagnostics]).decode()
    assert_html_safe(page)
    assert len(page) < limit
    console = Console(file=io.StringIO(), width=100)
    print_results(console, [result])
    shown = console.file.getvalue()  # type: ignore[attr-defined]
    assert raw_controls(shown) == [] and len(shown) < limit
    hil = HilResult(result)
    assert raw_controls(hil.explanation) == [] and len(hil.explanation) < limit
    assert raw_controls(repr(hil)) == []
    errors = io.StringIO()
    with contextlib.redirect_stderr(errors):
        _print_error(error)
    assert raw_controls(errors.getvalue()) == []
    grade = StudentGrade(scenario, "script", {"wall": "FAIL"}, result.first_failure or "")
    table = class_csv([grade], ["wall"]).decode().replace("\r\n", "\n")
    assert raw_controls(table) == [] and len(table) < limit
    assert_html_safe(class_html([grade], ["wall"]).decode())
    console = Console(file=io.StringIO(), width=100)
    console.print(class_rich_table([grade], ["wall"]))
    assert raw_controls(console.file.getvalue()) == []  # type: ignore[attr-defined]


# -- a megabyte a tick -----------------------------------------------------------

PROCESSOR = """
from harness.reference.scan_logic import analyse_message, status_text

PAD = "." * 10_000  # the answer starts beyond what a record keeps


def process(scan, threshold):
    report = analyse_message(scan, threshold)
    return f"{PAD} {status_text(report)} " + "." * 1_000_000, report.warning


def wrong(scan, threshold):
    return f"{PAD} 9.5 m " + "." * 1_000_000, True
"""
# Two ticks: reading a megabyte takes the status parser about half a second.
SHORT_WALL = """\
description: A moment still, a wall 0.4 m ahead.
obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]
motion: {segments: [{until: {duration: 0.05}}]}
"""


@pytest.mark.timeout(120)
def test_a_megabyte_status_is_judged_whole_and_kept_short(tmp_path: Path) -> None:
    """The oracle reads all of a 1 MB status; reports keep 4096 characters and its length."""
    processor, scenario = tmp_path / "big.py", tmp_path / "short_wall.yaml"
    processor.write_text(PROCESSOR)
    scenario.write_text(SHORT_WALL)
    out = tmp_path / "report"
    done = fossbot_hil(
        "run", str(scenario), "--link", "inprocess", "--processor", f"{processor}:process",
        "--out", str(out), timeout=100,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr  # only the whole text is right
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    assert size < 1_000_000  # no file keeps even one status whole
    details = json.loads((out / "scenarios" / "short_wall.json").read_text())
    status = details["records"][0]["status"]
    assert len(status) <= TEXT_LIMIT and status.startswith("." * 1000)
    note = status[status.rindex("… [") :]
    total, dropped = (int(n) for n in re.findall(r"\d+", note))
    assert total > 1_010_000 and total - dropped == len(status) - len(note)  # length noted

    wrong = fossbot_hil(
        "run", str(scenario), "--link", "inprocess", "--processor", f"{processor}:wrong",
        "--out", str(out), timeout=100,
    )  # fmt: skip
    assert wrong.returncode == 1, wrong.stdout + wrong.stderr
    summary = json.loads((out / "summary.json").read_text())
    first = summary["scenarios"][0]["first_failure"]
    assert "gives 9.50 m" in first  # judged on the part beyond the clip
    assert "not kept]" in first and len(first) < 2_000
    assert len(wrong.stdout) < 20_000
