"""Fixtures for the `run --watch` tests: the command as a child process, a student's
script to edit, and a verdict cache of each test's own.

Nothing here imports rclpy: the tests of pure parts run without ROS; the ones
that run ROS nodes carry the `ros` mark.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

pytest.register_assert_rewrite("watch_process")

from watch_process import WatchProcess  # noqa: E402


@pytest.fixture(autouse=True)
def cache_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The verdict cache of this test alone (the commands it starts inherit it)."""
    home = tmp_path / "cache"
    monkeypatch.setenv("FOSSBOT_HIL_CACHE_DIR", str(home))
    return home


@pytest.fixture
def start_watch(tmp_path: Path) -> Iterator[Callable[..., WatchProcess]]:
    """Start `fossbot-hil run ARGS --watch` in a folder (tmp_path by default); killed at
    teardown if a test left it running."""
    started: list[WatchProcess] = []

    def start(*args: str, cwd: Path | None = None) -> WatchProcess:
        process = WatchProcess(args, cwd=cwd or tmp_path, env={})
        started.append(process)
        return process

    yield start
    for process in started:
        process.kill()
