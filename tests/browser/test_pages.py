"""index.html, grades.html and a student's report in headless Chromium at 1280 px.

Each page, served over localhost HTTP: it renders (no script or console error,
no failed request, its headline and rows laid out and visible), every image
loads once scrolled to (they load lazily), every link resolves to a file
inside the folder the command wrote (or to an element of the page, for a
fragment), and nothing reaches past the right edge of a 1280 px wide window.
The run's page is compared with a baseline (its widest table); grades.html is
also laid out at its widest, with a column for every shipped scenario.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urldefrag, urlsplit

import pytest
from browser_pages import HEIGHT, SCENARIOS, STUDENTS, WAIT_MS, WIDTH, Built, Server

from harness.grading.class_table import StudentGrade, class_html
from harness.scenario.files import shipped_scenarios

pytestmark = [pytest.mark.slow, pytest.mark.timeout(300)]

PACKAGE = "fossbot_lidar_processing"
ARTIFACTS = (("report", "report/index.html"), ("run log", "run.log"), ("JUnit", "junit.xml"))
FAILURE = (  # as the oracle words one
    "noisy_approach: t=0.00 s tick 0: nearest valid return 1.458 m at 0.042 rad (beam 3); "
    "threshold 0.50 m; expected distance 1.4584 m (± 0.0500); status 'Min distance: 1.2 m, "
    "angle: 0.04 rad' claims 1.2 m"
)
BUILD_ERROR = (
    "did not build: setup.py line 18: SyntaxError: invalid syntax. Perhaps you forgot a comma?"
)


@dataclass(frozen=True)
class Page:
    """A page to test: the file, the folder its links must stay in, what it must show."""

    file: Path
    site: Path
    texts: tuple[str, ...]  # visible on the page
    images: int  # at least this many <img>
    links: int  # at least this many <a href>


def _run_page(built: Built) -> Page:
    site = built.folder / "run"
    return Page(site / "index.html", site, ("1 of 2 scenarios passed", *SCENARIOS), 4, 10)


def _class_page(built: Built) -> Page:
    site = built.folder / "grades"
    return Page(site / "grades.html", site, (*STUDENTS, *SCENARIOS), 0, 3 * len(STUDENTS))


def _report_page(built: Built, student: str) -> Page:
    own = built.folder / "grades" / "students" / student
    return Page(own / "report" / "index.html", own, SCENARIOS, 2, 8)


PAGES = {
    "index.html": ("run_site", _run_page),
    "grades.html": ("class_site", _class_page),
    **{
        f"report of {name}": ("class_site", partial(_report_page, student=name))
        for name in STUDENTS
    },
}


@pytest.fixture(
    scope="module",
    params=[
        pytest.param(name, marks=[pytest.mark.ros] if site == "class_site" else [])
        for name, (site, _) in PAGES.items()
    ],
)
def page_spec(request: pytest.FixtureRequest) -> Page:
    site, make = PAGES[request.param]
    return make(request.getfixturevalue(site))


@dataclass
class Loaded:
    """A page open in its own browser context (loaded once for the tests of this module),
    and every problem seen while loading it or scrolling through it."""

    page: Any
    spec: Page
    url: str
    problems: list[str] = field(default_factory=list)


def _console(seen: Loaded, message: Any) -> None:
    """An error in the console, but the browser's own asking for /favicon.ico (a report
    folder has none, and needs none)."""
    where = message.location.get("url", "")
    if message.type == "error" and not where.endswith("/favicon.ico"):
        seen.problems.append(f"console {message.type}: {message.text} ({where})")


@pytest.fixture(scope="module")
def loaded(browser: Any, server: Server, page_spec: Page) -> Iterator[Loaded]:
    context = browser.new_context(viewport={"width": WIDTH, "height": HEIGHT})
    context.set_default_timeout(WAIT_MS)
    page = context.new_page()
    url = server.url_of(page_spec.file)
    seen = Loaded(page, page_spec, url)
    page.on("console", lambda m: _console(seen, m))
    page.on("pageerror", lambda e: seen.problems.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: seen.problems.append(f"failed: {r.url} {r.failure}"))
    page.on(
        "response",
        lambda r: seen.problems.append(f"HTTP {r.status}: {r.url}") if r.status >= 400 else 0,
    )
    response = page.goto(url, wait_until="load")
    assert response is not None and response.status == 200, url
    page.evaluate("document.fonts.ready.then(() => true)")
    yield seen
    context.close()


def test_page_renders(loaded: Loaded) -> None:
    """A title, one headline, the expected names as visible text, no error on the way."""
    page = loaded.page
    assert page.title()
    assert page.locator("h1").count() == 1 and page.locator("h1").is_visible()
    text = page.inner_text("body")
    for expected in loaded.spec.texts:
        assert expected in text, (expected, text[:2000])
    rows = page.evaluate(
        "[...document.querySelectorAll('table tr')].map(r => r.getBoundingClientRect().height)"
    )
    assert len(rows) >= 3 and all(height > 0 for height in rows), rows
    height = page.evaluate("document.documentElement.scrollHeight")
    assert height > 200, f"the page is {height} px high"
    assert not loaded.problems, loaded.problems


def test_every_image_loads(loaded: Loaded) -> None:
    """Each <img>, scrolled to (they load lazily), is a decoded picture."""
    page = loaded.page
    images = page.locator("img")
    assert images.count() >= loaded.spec.images
    broken = []
    for i in range(images.count()):
        image = images.nth(i)
        image.scroll_into_view_if_needed()
        handle = image.element_handle()
        page.wait_for_function("img => img.complete", arg=handle, timeout=WAIT_MS)
        natural = handle.evaluate("img => [img.naturalWidth, img.naturalHeight]")
        box = image.bounding_box()
        if natural[0] == 0 or natural[1] == 0 or not box or box["width"] < 1:
            broken.append((image.get_attribute("src"), natural, box))
    assert not broken, broken
    assert not loaded.problems, loaded.problems


def test_every_link_resolves(loaded: Loaded, server: Server) -> None:
    """A fragment names an element of the page; any other link is relative, names a file
    inside the folder the command wrote, and loads (HTTP 200, not empty)."""
    page = loaded.page
    links = page.eval_on_selector_all(
        "a[href]", "as => as.map(a => [a.getAttribute('href'), a.href])"
    )
    assert len(links) >= loaded.spec.links, links
    site = loaded.spec.site.resolve()
    here = urldefrag(loaded.url).url
    problems = []
    for written, absolute in links:
        target, fragment = urldefrag(absolute)
        if target == here:
            found = page.evaluate("id => document.getElementById(id) !== null", unquote(fragment))
            if not (fragment and found):
                problems.append(f"{written}: no element with that id on the page")
            continue
        if urlsplit(written).scheme or written.startswith("/"):
            problems.append(f"{written}: not a relative link")
            continue
        file = (server.root / unquote(urlsplit(target).path).lstrip("/")).resolve()
        if not file.is_relative_to(site):
            problems.append(f"{written}: outside {site.name}/")
            continue
        if not file.is_file():
            problems.append(f"{written}: no such file")
            continue
        served = page.context.request.get(target, timeout=WAIT_MS)
        if served.status != 200 or not served.body():
            problems.append(f"{written}: HTTP {served.status}, {len(served.body())} bytes")
    assert not problems, problems


_PAST_THE_EDGE = """
width => {
  // a <pre> (a node's output) scrolls on its own: its lines may be wider than it
  const clipped = el => {
    const pre = el.parentElement && el.parentElement.closest('pre');
    return pre !== null && getComputedStyle(pre).overflowX !== 'visible';
  };
  const out = [];
  for (const el of document.body.querySelectorAll('*')) {
    const r = el.getBoundingClientRect();
    if ((r.width === 0 && r.height === 0) || clipped(el)) continue;
    if (r.right + window.scrollX > width + 0.5) {
      const text = (el.textContent || '').trim().slice(0, 60);
      out.push(`<${el.tagName.toLowerCase()} class="${el.className}"> right ${r.right}: ${text}`);
    }
  }
  return out;
}
"""


def _overflow(page: Any) -> tuple[list[int], list[str]]:
    """The document's widths, and every element that ends right of 1280 px."""
    widths = page.evaluate("[document.documentElement.scrollWidth, document.body.scrollWidth]")
    return widths, page.evaluate(_PAST_THE_EDGE, WIDTH)


def test_nothing_overflows_at_1280_px(loaded: Loaded) -> None:
    """No horizontal scrolling: the document and every element end within 1280 px (but
    the lines inside a <pre>, which scrolls on its own)."""
    widths, past = _overflow(loaded.page)
    assert max(widths) <= WIDTH and not past, (widths, past[:20])


def test_a_class_graded_on_every_shipped_scenario_fits_1280_px(
    browser: Any, server: Server, tmp_path: Path
) -> None:
    """grades.html at its widest as grade makes it by default: a column for each shipped
    scenario, and the lab's usual hand-in (a workspace, named as an LMS names folders),
    beside a failure and a build error. (A real class on every scenario takes a minute;
    the rows here are StudentGrade values as grade fills them.)"""
    scenarios = [s.name for s in shipped_scenarios()]
    assert len(scenarios) >= 7, scenarios
    workspace = f"{PACKAGE}/fossbot_lidar_node (workspace)"
    files = tuple((label, f"students/x/{name}") for label, name in ARTIFACTS)
    every = dict.fromkeys(scenarios, (95, 95))
    grades = [
        StudentGrade(
            name="Jane Doe_1234567_assignsubmission_file_",
            kind="workspace",
            verdicts=dict.fromkeys(scenarios, "PASS"),
            ticks=every,
            node=workspace,
            artifacts=files,
        ),
        StudentGrade(
            name="bob",
            kind="package",
            verdicts={s: ("FAIL" if i % 2 else "PASS") for i, s in enumerate(scenarios)},
            ticks={s: (12 if i % 2 else 95, 95) for i, s in enumerate(scenarios)},
            node=workspace,
            artifacts=files,
            first_failure=FAILURE,
        ),
        StudentGrade(
            name="carol",
            kind="package",
            verdicts=dict.fromkeys(scenarios, "NOT RUN"),
            node=workspace,
            artifacts=files[:1],
            first_failure=BUILD_ERROR,
        ),
    ]
    file = tmp_path / "grades.html"
    file.write_bytes(class_html(grades, scenarios))
    context = browser.new_context(viewport={"width": WIDTH, "height": HEIGHT})
    try:
        page = context.new_page()
        page.goto(server.url_of(file), wait_until="load", timeout=WAIT_MS)
        rows = page.locator("tbody tr")
        assert rows.count() == len(grades)
        widths, past = _overflow(page)
        assert max(widths) <= WIDTH and not past, (widths, past[:20])
    finally:
        context.close()
