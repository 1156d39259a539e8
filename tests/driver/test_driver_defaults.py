"""The bundled driver's defaults follow the FOSSBot v2 bridge (read from the source, no ROS)."""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import pytest

from harness.lidar.mount import LidarMount

PACKAGE = Path(__file__).resolve().parents[2] / "node" / "fossbot_lidar_driver"
NODES = ("rplidar_node", "ldlidar_node")
V2 = LidarMount(yaw_deg=-90.0)  # the v2's A1: zero to the robot's right, clockwise


def node_defaults(module: str) -> dict[str, Any]:
    """The DEFAULTS dict of a node module, read without importing rclpy."""
    tree = ast.parse((PACKAGE / "fossbot_lidar_driver" / f"{module}.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.AnnAssign) and node.value is not None:
            targets, value = [node.target], node.value
        elif isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        else:
            continue
        if any(isinstance(t, ast.Name) and t.id == "DEFAULTS" for t in targets):
            return ast.literal_eval(value)
    raise AssertionError(f"{module}: no DEFAULTS")


@pytest.mark.parametrize("module", NODES)
def test_both_nodes_default_to_the_v2_bridges_mapping(module: str) -> None:
    """invert true, angle_offset_deg -90: the v2 mount's driver settings."""
    defaults = node_defaults(module)
    assert (defaults["invert"], defaults["angle_offset_deg"]) == V2.driver_settings()
    assert isinstance(defaults["angle_offset_deg"], float)  # a ROS double parameter


def test_the_readme_table_says_the_same() -> None:
    """The parameters table in the package README shows the defaults the code has."""
    readme = (PACKAGE / "README.md").read_text()
    assert "| `angle_offset_deg` | `-90.0` | `-90.0` |" in readme
    assert "| `invert` | `true` | `true` |" in readme
