"""Failed scenarios first, and the verdicts kept between commands for it."""

from __future__ import annotations

import json
import os
from pathlib import Path

from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.watch.order import failed_first
from harness.watch.verdict_cache import cache_folder, verdict_cache


def result(name: str, ok: bool = True, *, not_run: bool = False) -> RunResult:
    error = None if ok else "it failed"
    return RunResult(name, "ros2", 0, 0.5, "clean", error=error, not_run=not_run)


def test_failed_first_keeps_each_part_in_its_order() -> None:
    """Like pytest --ff: the failures in their given order, then the rest in theirs."""
    names = ["a", "b", "c", "d", "e"]
    assert failed_first(names, {"d", "b"}, name=str) == ["b", "d", "a", "c", "e"]
    assert failed_first(names, set(), name=str) == names
    assert failed_first(names, {"zzz"}, name=str) == names
    assert failed_first(["a", "b", "a"], {"a"}, name=str) == ["a", "a", "b"]


def test_the_cache_folder_follows_xdg(tmp_path: Path) -> None:
    """$XDG_CACHE_HOME, else ~/.cache, as any other tool's cache; FOSSBOT_HIL_CACHE_DIR
    names one of its own."""
    assert cache_folder({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "fossbot-hil/last-run"
    home = Path(os.path.expanduser("~"))
    assert cache_folder({}) == home / ".cache/fossbot-hil/last-run"
    assert cache_folder({"XDG_CACHE_HOME": "relative"}) == home / ".cache/fossbot-hil/last-run"
    own = {"FOSSBOT_HIL_CACHE_DIR": str(tmp_path / "ci"), "XDG_CACHE_HOME": str(tmp_path)}
    assert cache_folder(own) == tmp_path / "ci" / "last-run"


def test_verdicts_are_kept_and_merged(tmp_path: Path) -> None:
    """A run's verdicts replace the earlier ones of the same scenarios, others stay."""
    cache = verdict_cache("ros2", LinkOptions(node="python3 n.py"), cwd="/lab", folder=tmp_path)
    assert cache.failed() == set()  # no earlier run: the given order
    cache.remember([result("a", False), result("b")])
    assert cache.failed() == {"a"}
    cache.remember([result("a"), result("c", False)])
    assert cache.verdicts() == {"a": "passed", "b": "passed", "c": "failed"}


def test_what_was_not_judged_is_not_kept(tmp_path: Path) -> None:
    """A scenario not run, or the one a Ctrl-C stopped, keeps its earlier verdict."""
    cache = verdict_cache("ros2", LinkOptions(), cwd="/lab", folder=tmp_path)
    cache.remember([result("a", False), result("b", False), result("c", False)])
    cache.remember([result("a"), result("b"), result("c", not_run=True)], interrupted=True)
    assert cache.verdicts() == {"a": "passed", "b": "failed", "c": "failed"}


def test_each_folder_and_node_has_its_own(tmp_path: Path) -> None:
    """Another node, or the same command line from another folder, starts afresh."""
    node = LinkOptions(node="python3 node.py")
    verdict_cache("ros2", node, cwd="/lab", folder=tmp_path).remember([result("a", False)])
    for link, options, cwd in [
        ("ros2", LinkOptions(node="python3 other.py"), "/lab"),
        ("ros2", node, "/elsewhere"),
        ("rplidar", node, "/lab"),
        ("ros2", LinkOptions(package="p", executable="e", workspace="/ws"), "/lab"),
    ]:
        assert verdict_cache(link, options, cwd=cwd, folder=tmp_path).failed() == set()
    assert verdict_cache("ros2", node, cwd="/lab", folder=tmp_path).failed() == {"a"}


def test_a_bad_file_means_the_given_order(tmp_path: Path) -> None:
    """Unreadable, of another format or another key: no order, no error."""
    cache = verdict_cache("ros2", LinkOptions(), cwd="/lab", folder=tmp_path)
    cache.remember([result("a", False)])
    good = json.loads(cache.path.read_text())
    for content in [
        "{not json",
        "[]",
        json.dumps({**good, "format": 99}),
        json.dumps({**good, "key": {"cwd": "/other"}}),
        json.dumps({**good, "verdicts": ["a"]}),
        json.dumps({**good, "verdicts": {"a": "maybe"}}),
    ]:
        cache.path.write_text(content)
        assert cache.failed() == set(), content
    cache.remember([result("b", False)])  # and the next run writes a good one again
    assert cache.failed() == {"b"}


def test_an_unwritable_cache_is_no_error(tmp_path: Path) -> None:
    """The order is a convenience: a cache that cannot be written is skipped."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    cache = verdict_cache("ros2", LinkOptions(), cwd="/lab", folder=blocker / "sub")
    cache.remember([result("a", False)])
    assert cache.failed() == set()


def test_only_the_newest_files_are_kept(tmp_path: Path, monkeypatch) -> None:
    """One file per folder and node, the oldest removed past KEPT_FILES."""
    monkeypatch.setattr("harness.watch.verdict_cache.KEPT_FILES", 3)
    for index in range(5):
        cache = verdict_cache("ros2", LinkOptions(), cwd=f"/lab{index}", folder=tmp_path)
        cache.remember([result("a")])
        os.utime(cache.path, (index, index))  # written in this order
    left = {json.loads(p.read_text())["key"]["cwd"] for p in tmp_path.glob("*.json")}
    assert left == {"/lab2", "/lab3", "/lab4"}
