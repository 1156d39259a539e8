"""Before the first scan: the node reading the scans is named by discovery, bounded."""

from __future__ import annotations

import pytest

from harness.links.base import LinkOptions
from harness.links.ros2 import NAMED_WAIT_S, Ros2Link
from harness.ros.observer import Observer
from harness.runner.scenario_run import run
from harness.scenario.files import resolve_scenario


def test_the_reference_nodes_scan_reader_is_named_once_the_link_is_open() -> None:
    """Opening waits until discovery names the node that reads the scans (its side has
    matched the harness's then, so the first scan is not repaired late)."""
    named: list[bool] = []
    opened = Ros2Link.open

    def recording_open(link: Ros2Link) -> None:
        opened(link)
        assert link.observer is not None
        named.append(link.observer.scan_readers_named())

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Ros2Link, "open", recording_open)
        result = run(resolve_scenario("out_of_range"), "ros2", LinkOptions())
    assert result.ok, result.first_failure
    assert named == [True]


def test_a_reader_never_named_gets_its_scans_after_the_bounded_wait(monkeypatch) -> None:
    """A participant that never announces its node (no ROS node behind it) is not kept
    waiting for ever: after NAMED_WAIT_S its first scan goes, and the run is judged."""
    monkeypatch.setattr(Observer, "scan_readers_named", lambda self: False)
    result = run(resolve_scenario("out_of_range"), "ros2", LinkOptions())
    assert result.ok, result.first_failure
    assert result.startup_s >= NAMED_WAIT_S
