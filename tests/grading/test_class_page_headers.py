"""grades.html's scenario columns: a narrow column's header breaks only after an underscore
("approach_" / "wall"), never inside a word ("appro ach_w all" was hard to read); and the
audit's line is on the page. Rendered by Debian's Chromium through Playwright (skipped
without them, except under CI), the page as grade writes it for a class graded on every
shipped scenario."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from typing import Any

import pytest

from harness.grading.class_table import StudentGrade, class_html
from harness.scenario.files import shipped_scenarios

WIDTH, HEIGHT = 1280, 800
WAIT_MS = 10_000  # every wait in the browser is bounded by this
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-sync"]
FAILURE = (
    "approach_wall: t=3.20 s tick 32: nearest valid return 0.412 m at 0.000 rad; threshold "
    "0.5 m; expected: warning True; got: warning False (the node published none this scan)"
)
# Each header's text as the browser laid it out, one string per line.
HEADER_LINES = """
() => [...document.querySelectorAll('th.scenario')].map(th => {
  const lines = [];
  let top = null;
  const walker = document.createTreeWalker(th, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    for (let i = 0; i < node.length; i++) {
      const range = document.createRange();
      range.setStart(node, i);
      range.setEnd(node, i + 1);
      const box = range.getBoundingClientRect();
      if (box.width === 0 && box.height === 0) continue;
      if (top === null || Math.abs(box.top - top) > 2) { lines.push(''); top = box.top; }
      lines[lines.length - 1] += node.data[i];
    }
  }
  return lines;
})
"""


def page(scenarios: list[str], audit: str | None = None) -> str:
    """The class page at its narrowest columns: every shipped scenario, long names and a
    long first failure beside them."""
    workspace = "fossbot_lidar_processing/fossbot_lidar_node (workspace)"
    grades = [
        StudentGrade(
            "Jane Doe_1234567_assignsubmission_file_",
            "workspace",
            dict.fromkeys(scenarios, "PASS"),
            ticks=dict.fromkeys(scenarios, (95, 95)),
            node=workspace,
        ),
        StudentGrade(
            "bob",
            "package",
            {s: ("FAIL" if i % 2 else "PASS") for i, s in enumerate(scenarios)},
            FAILURE,
            ticks={s: (12 if i % 2 else 95, 95) for i, s in enumerate(scenarios)},
            node=workspace,
        ),
    ]
    return class_html(grades, scenarios, max_score=10, audit=audit).decode()


def test_headers_can_break_only_after_an_underscore() -> None:
    """The markup offers a break after each underscore and none inside a word: each piece
    an inline block."""
    html = page(["approach_wall", "drive_past_10m", "<x>_y"])
    assert '<th class="scenario"><span>approach_</span><span>wall</span></th>' in html
    assert "<span>drive_</span><span>past_</span><span>10m</span></th>" in html
    assert "<span>&lt;x&gt;_</span><span>y</span></th>" in html
    assert "th.scenario span { display: inline-block; }" in html
    assert "th.scenario, td.student { overflow-wrap: anywhere; }" not in html


def test_the_page_shows_the_audit_line_above_the_table() -> None:
    line = "warning: the audit could not run: goes_silent: stopped after 630 s <b>"
    html = page(["approach_wall"], audit=line)
    assert '<p class="audit">warning: the audit could not run: goes_silent: stopped after' in html
    assert html.index('class="audit"') < html.index("<table>")
    assert "<b>" not in html and "&lt;b&gt;" in html


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    """Headless Chromium, or a skip saying what is missing (a failure under CI)."""
    path = os.environ.get("FOSSBOT_HIL_CHROMIUM") or shutil.which("chromium")
    missing = None if path else "Chromium is not installed: apt-get install chromium"
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        missing = "Playwright is not installed: pip install '.[test]'"
    if missing:
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but {missing}", pytrace=False)
        pytest.skip(missing)
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(
            executable_path=path, args=CHROMIUM_ARGS, timeout=30_000
        )
        yield launched
        launched.close()


def test_every_shipped_scenario_header_reads_whole_words_at_1280_px(browser: Any) -> None:
    """Laid out at 1280 px, each header's lines end at an underscore (or it is one line),
    and together they spell the scenario's name."""
    scenarios = [s.name for s in shipped_scenarios()]
    context = browser.new_context(viewport={"width": WIDTH, "height": HEIGHT})
    try:
        tab = context.new_page()
        tab.set_content(page(scenarios), wait_until="load", timeout=WAIT_MS)
        laid_out = dict(zip(scenarios, tab.evaluate(HEADER_LINES), strict=True))
        width = tab.evaluate("document.documentElement.scrollWidth")
    finally:
        context.close()
    for name, lines in laid_out.items():
        assert "".join(lines) == name, laid_out
        assert all(line.endswith("_") for line in lines[:-1]), laid_out
    assert any(len(lines) > 1 for lines in laid_out.values()), laid_out  # columns are narrow
    assert width <= WIDTH, width
