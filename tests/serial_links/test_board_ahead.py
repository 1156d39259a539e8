"""The virtual board's next node, started ahead: which links may, and the topics of its
own it answers on (so nothing it says reaches the running scenario's judging)."""

from __future__ import annotations

from harness.devices.profiles import PROFILES
from harness.links.base import LinkOptions
from harness.links.board_session import OWN_TOPICS, BoardSession, takes_remaps
from harness.links.rplidar import RplidarLink
from harness.nodes.command import NodeCommand


def test_the_virtual_boards_next_link_starts_ahead_a_physical_boards_none() -> None:
    assert RplidarLink.links_ahead(LinkOptions()) == 1
    assert RplidarLink.links_ahead(LinkOptions(port="/dev/ttyUSB0")) == 0


def test_a_node_a_launch_file_starts_cannot_be_remapped() -> None:
    assert takes_remaps(NodeCommand(("python3", "node.py")))
    launched = NodeCommand(("ros2", "launch", "p", "f.py"), launch_arguments=frozenset())
    assert not takes_remaps(launched)


def test_each_node_gets_status_and_warning_topics_of_its_own() -> None:
    session = BoardSession(PROFILES["rplidar"], LinkOptions())
    first = session.node_topics("/lidar_status", "/obstacle_warning")
    second = session.node_topics("lidar_status", "/robot/obstacle_warning")
    assert first == (f"{OWN_TOPICS}/node1/lidar_status", f"{OWN_TOPICS}/node1/obstacle_warning")
    assert second == (
        f"{OWN_TOPICS}/node2/lidar_status",
        f"{OWN_TOPICS}/node2/robot/obstacle_warning",
    )
    assert session.node_topics("~/status", "/w") is None  # a private name: not remapped


def test_private_topic_names_start_nothing_ahead() -> None:
    assert RplidarLink.links_ahead(LinkOptions(status_topic="~/status")) == 0
