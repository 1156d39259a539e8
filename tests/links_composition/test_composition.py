"""Links by composition (issue 40, item 4): no link class subclasses another, the node
exchange owns the waits and a delivery plugs into it, a serial LIDAR is its name and its
device profile, and no module of the links is over 600 lines.

The link modules are imported (no rclpy, no processes started) and read as source.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

from harness.devices.profiles import PROFILES
from harness.links.base import Link, LinkOptions, link_class
from harness.links.kinds import KINDS

LINKS = Path(__file__).resolve().parents[2] / "harness" / "links"
TOY_LINK = Path(__file__).resolve().parents[1] / "serial_links" / "toy_lidar" / "link.py"
SHIPPED = [name for name, kind in KINDS.items() if kind.module.startswith("harness.links.")]


def _link_classes() -> list[type[Link]]:
    found: list[type[Link]] = []
    for path in sorted(LINKS.glob("*.py")):
        module = importlib.import_module(f"harness.links.{path.stem}")
        found += [
            cls
            for _, cls in inspect.getmembers(module, inspect.isclass)
            if issubclass(cls, Link) and cls is not Link and cls.__module__ == module.__name__
        ]
    return found


def test_no_link_class_subclasses_another() -> None:
    """Each link class's only base is the abstract ``Link``: no link, no link mixin."""
    classes = _link_classes()
    assert {cls.__name__ for cls in classes} >= {"Ros2Link", "BoardLink", "InprocessLink"}
    assert [c.__name__ for c in classes if c.__bases__ != (Link,)] == []


def test_the_toy_lidars_link_subclasses_nothing() -> None:
    tree = ast.parse(TOY_LINK.read_text())
    assert not [node.name for node in ast.walk(tree) if isinstance(node, ast.ClassDef)]


@pytest.mark.parametrize("name", [n for n in SHIPPED if KINDS[n].serial_line])
def test_a_serial_lidar_is_a_board_link_with_its_device_profile(name: str) -> None:
    from harness.links.board import BoardLink

    link = link_class(name)(LinkOptions())  # nothing starts before `start`
    assert type(link) is BoardLink and link.name == name
    assert link.profile is PROFILES[str(KINDS[name].device)]


def test_both_links_compose_the_one_exchange_with_their_delivery() -> None:
    from harness.links.board_delivery import BoardDelivery
    from harness.links.node_exchange import NodeExchange
    from harness.links.ros2 import TopicDelivery

    ros2, board = link_class("ros2")(LinkOptions()), link_class("rplidar")(LinkOptions())
    assert type(ros2.node_exchange) is type(board.node_exchange) is NodeExchange
    assert isinstance(ros2.node_exchange.delivery, TopicDelivery)
    assert isinstance(board.node_exchange.delivery, BoardDelivery)
    assert (
        ros2.node_exchange.delivery.copies_queue and not board.node_exchange.delivery.copies_queue
    )


def test_the_board_session_reads_the_bounds_not_the_ros2_link() -> None:
    tree = ast.parse((LINKS / "board_session.py").read_text())
    imported = {
        node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
    }
    assert "harness.links.ros2" not in imported and "harness.links.bounds" in imported


def test_no_module_of_the_links_is_over_600_lines() -> None:
    long = {p.name: n for p in LINKS.glob("*.py") if (n := len(p.read_text().splitlines())) > 600}
    assert long == {}
