"""The suite's links in order: started ahead, stopped behind, all closed at the end."""

from __future__ import annotations

import pytest

from harness.links.base import Link, LinkOptions
from harness.runner.link_pipeline import AHEAD, BEHIND, LinkPipeline, ReportsBehind


class Recorded(Link):
    """A link that only notes what was asked of it, in one shared log."""

    name = "recorded"

    def __init__(self, index: int, log: list[str]) -> None:
        super().__init__(LinkOptions())
        self.index, self.log = index, log

    def start(self) -> None:
        self.log.append(f"start {self.index}")

    def stop(self) -> None:
        self.log.append(f"stop {self.index}")

    def close(self) -> None:
        self.log.append(f"close {self.index}")

    def send(self, scan, tick, *, clock=None):  # pragma: no cover - never called here
        raise AssertionError

    def collect(self, scan, tick, *, may_be_ignored=False):  # pragma: no cover
        raise AssertionError


def pipeline(count: int, *, overlap: bool) -> tuple[LinkPipeline, list[str]]:
    log: list[str] = []
    return LinkPipeline(lambda i: Recorded(i, log), count, overlap=overlap), log


def test_without_overlap_each_link_starts_runs_and_closes_in_turn() -> None:
    links, log = pipeline(3, overlap=False)
    closed: list[int] = []
    for i in range(3):
        link = links.take(i)
        log.append(f"run {i}")
        links.retire(link, lambda waited, i=i: closed.append(i))
    links.drain()
    assert log == [
        *("start 0", "run 0", "stop 0", "close 0"),
        *("start 1", "run 1", "stop 1", "close 1"),
        *("start 2", "run 2", "stop 2", "close 2"),
    ]
    assert closed == [0, 1, 2]


def test_with_overlap_links_start_ahead_and_close_behind_in_order() -> None:
    count = AHEAD + BEHIND + 3
    links, log = pipeline(count, overlap=True)
    closed: list[int] = []
    for i in range(count):
        link = links.take(i)
        started = [int(e.split()[1]) for e in log if e.startswith("start")]
        assert started == list(range(min(i + AHEAD, count - 1) + 1))  # never more ahead
        log.append(f"run {i}")
        links.retire(link, lambda waited, i=i: closed.append(i))
        assert len([e for e in log if e.startswith("stop")]) - len(closed) <= BEHIND
    links.drain()
    assert closed == list(range(count))  # reported in scenario order
    for i in range(count):  # each link: started, run, asked to stop, then closed
        mine = [e for e in log if e.endswith(f" {i}")]
        assert mine == [f"start {i}", f"run {i}", f"stop {i}", f"close {i}"]


def test_drain_closes_links_started_ahead_and_never_taken() -> None:
    links, log = pipeline(AHEAD + 3, overlap=True)
    link = links.take(0)
    links.retire(link, lambda waited: None)
    links.drain()  # e.g. the node did not start: the rest are not run
    assert {e for e in log if e.startswith("close")} == {f"close {i}" for i in range(AHEAD + 1)}
    assert not any(e.startswith(f"start {AHEAD + 1}") for e in log)  # no more were started


def test_links_are_taken_in_order() -> None:
    links, _ = pipeline(3, overlap=True)
    with pytest.raises(ValueError, match="in order"):
        links.take(1)


def test_drain_closes_a_link_whose_run_raised() -> None:
    links, log = pipeline(3, overlap=False)
    links.take(0)  # its run raised: never retired
    links.drain()
    links.drain()  # again: nothing more to do
    assert log == ["start 0", "stop 0", "close 0"]


def test_a_serial_links_pipeline_starts_the_next_one_ahead_and_leaves_none_behind() -> None:
    """ahead=1, behind=0 (a board's links share one device): while scenario i runs, only
    i + 1 is up beside it, and i is closed before i + 1 is taken."""
    log: list[str] = []
    links = LinkPipeline(lambda i: Recorded(i, log), 3, overlap=True, ahead=1, behind=0)
    link = links.take(0)
    assert log == ["start 0", "start 1"]
    links.retire(link, lambda waited: None)
    assert log[-2:] == ["stop 0", "close 0"]
    link = links.take(1)
    assert log[-1] == "start 2"
    links.retire(link, lambda waited: None)
    links.drain()
    assert [e for e in log if e.startswith("close")] == ["close 0", "close 1", "close 2"]


def test_reports_behind_wait_for_finish_and_come_in_order() -> None:
    """Reports behind (a serial link's device streams in real time): none while the
    suite runs, all in order at finish, once."""
    seen: list[int] = []
    reports = ReportsBehind(seen.append, behind=True)
    for i in range(5):
        reports(i)
    assert seen == []
    reports.finish()
    reports.finish()
    assert seen == [0, 1, 2, 3, 4]


def test_reports_not_behind_are_made_at_once() -> None:
    seen: list[int] = []
    reports = ReportsBehind(seen.append, behind=False)
    reports(3)
    assert seen == [3]
    reports.finish()
