"""The sentences that say why a node did not come up or never answered, without a graph."""

from __future__ import annotations

import numpy as np

from harness.lidar.scan import Scan
from harness.links.base import LinkOptions
from harness.links.start_explanations import (
    never_answered,
    never_ready,
    ready_bound_said,
    unheard,
)

NODE = "python3 lidar_node.py"


def test_the_bound_is_said_with_an_early_end() -> None:
    assert ready_bound_said(20.0, None) == "20 s"
    assert ready_bound_said(20.0, 1.23) == (
        "1.2 s (of the 20 s allowed: it uses other topics, seen for 1 s)"
    )


def test_never_ready_names_what_was_missing_and_the_clock() -> None:
    said = never_ready(
        NODE,
        LinkOptions(),
        reads=False,
        publishes=True,
        clock_all_along=False,
        waited="20 s",
        graph="no other node in this ROS domain",
    )
    assert said.startswith(f"node {NODE} never became ready within 20 s: ")
    assert "but it did not subscribe to /scan (the harness publishes /clock only once" in said
    assert said.endswith("(no other node in this ROS domain)")
    ready_late = never_ready(
        NODE,
        LinkOptions(),
        reads=True,
        publishes=True,
        clock_all_along=True,
        waited="20 s",
        graph="",
    )
    assert "it was ready only as time ran out" in ready_late and "/clock" not in ready_late


def test_unheard_prefers_the_wrong_type() -> None:
    assert unheard(NODE, ["/lidar_status: std_msgs/Float32"], ["x"]) is not None
    assert "wrong message type" in (unheard(NODE, ["t"], []) or "")
    assert unheard(NODE, [], ["best effort"]) == f"node {NODE} cannot be heard: best effort"
    assert unheard(NODE, [], []) is None


def scan(ranges: list[float]) -> Scan:
    n = len(ranges)
    step = 2 * np.pi / n
    return Scan(0.0, step * (n - 1), step, 0.1 / n, 0.1, 0.15, 12.0, np.array(ranges))


def test_silent_on_an_empty_first_scan_says_a_status_is_expected() -> None:
    empty = never_answered(NODE, LinkOptions(), scan([float("inf")] * 8), 3)
    assert "none of which had a valid return" in empty and 'e.g. "no obstacle"' in empty
    silent = never_answered(NODE, LinkOptions(), scan([1.0] * 8), 3)
    assert silent == (
        f"node {NODE} never answered a scan within 20 s (it subscribes to /scan and publishes "
        "/lidar_status, but no status arrived)"
    )
