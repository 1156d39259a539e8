"""The HTML pages in a real browser: Debian's Chromium, driven by Playwright.

The pages come from real commands, made once per test session (and once for
all pytest-xdist workers, under a file lock): a `fossbot-hil run --out` over
the inprocess link (one scenario passing, one failing, with animations), and
a `fossbot-hil grade` of two script students over ROS 2, both on two shipped
scenarios shortened to a dozen ticks (browser_pages.SHORTENED). A local HTTP server
serves them, so a link works only if it is relative and points at a file
inside the folder the command wrote: an absolute path or a link out of the
folder fails as it would on a web server or in a CI artifact.

Without Chromium (or Playwright) the tests skip with the reason, except under
CI (the environment variable CI set), where .ci/run installs Chromium and the
tests must run.
"""

from __future__ import annotations

import functools
import os
import shutil
import threading
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest
from browser_pages import BUILD_WAIT_S, BUILDS, CHROMIUM_ARGS, Built, Server, built_once


def _chromium() -> str:
    """FOSSBOT_HIL_CHROMIUM (another Chromium or Chrome), else Debian's."""
    return os.environ.get("FOSSBOT_HIL_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"


def _missing(reason: str) -> None:
    """Skip locally; fail under CI, which must run the browser tests."""
    if os.environ.get("CI"):
        pytest.fail(f"CI is set but {reason} (.ci/run installs Debian's chromium)", pytrace=False)
    pytest.skip(reason)


@pytest.fixture(scope="session")
def chromium() -> str:
    """The Chromium executable, or a skip (a failure under CI) saying what is missing."""
    path = _chromium()
    if not os.access(path, os.X_OK):
        _missing(f"Chromium is not installed ({path}): apt-get install chromium")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        _missing("Playwright is not installed: pip install '.[test]'")
    return path


@pytest.fixture(scope="module")
def browser(chromium: str) -> Iterator[Any]:
    """One headless Chromium for the browser tests of a module, stopped when the process
    moves on: Playwright's sync API keeps an asyncio loop running in this thread while it
    is open, and another module's asyncio.run() (e.g. the live view's) would then fail."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(
            executable_path=chromium, args=CHROMIUM_ARGS, timeout=30_000
        )
        yield launched
        launched.close()


# --- the pages, made by real commands ---------------------------------------------------


def _shared_folder(factory: pytest.TempPathFactory, name: str) -> Path:
    """A folder all xdist workers of this session share (this session's own with -n 0)."""
    base = factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    return base / name


@pytest.fixture(scope="session")
def _builds(
    chromium: str, request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[dict[str, Future[Built]]]:
    """The pages the selected tests need, made at once (most of their time is spent
    waiting for nodes, not computing). The class's tests are marked ros: grade runs its
    students over ROS 2."""
    here = Path(__file__).parent
    pages = {
        item.callspec.params.get("page_spec")
        for item in request.session.items
        if item.path.parent == here and hasattr(item, "callspec")
    }
    wanted = [name for name, (_, made) in BUILDS.items() if pages & set(made)]
    with ThreadPoolExecutor(max_workers=len(BUILDS), thread_name_prefix="browser-pages") as pool:
        yield {
            name: pool.submit(
                built_once, _shared_folder(tmp_path_factory, f"browser-{name}"), BUILDS[name][0]
            )
            for name in wanted
        }


@pytest.fixture(scope="session")
def run_site(_builds: dict[str, Future[Built]]) -> Built:
    """`fossbot-hil run --out baseline`, then `run --baseline baseline --out run` (exit 1:
    one scenario fails, on purpose)."""
    built = _builds["run"].result(timeout=BUILD_WAIT_S)
    assert built.returncodes == [0, 1], built.output
    assert (built.folder / "run" / "index.html").is_file(), built.output
    return built


@pytest.fixture(scope="session")
def class_site(_builds: dict[str, Future[Built]]) -> Built:
    """`fossbot-hil grade class --out grades`."""
    built = _builds["class"].result(timeout=BUILD_WAIT_S)
    assert built.returncodes == [0], built.output
    assert (built.folder / "grades" / "grades.html").is_file(), built.output
    return built


# --- serving them ----------------------------------------------------------------------


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002
        pass


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    root = _shared_folder(tmp_path_factory, "").resolve()
    handler = functools.partial(_QuietHandler, directory=str(root))
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, name="browser-tests-http", daemon=True)
    thread.start()
    yield Server(root, f"http://127.0.0.1:{httpd.server_address[1]}/")
    httpd.shutdown()
    httpd.server_close()
    thread.join(timeout=10)
