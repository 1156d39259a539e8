"""The URDF's joint chain, walked once for the LIDAR's mount and the live view alike."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from harness.errors import ConfigError
from harness.live.robot_mount import lidar_placement
from harness.scenario.mount import urdf_mount
from harness.scenario.urdf_chain import chain_to_root, joint_origin, joints_by_child

ROBOT = """<robot name="r">
  <link name="base"/><link name="plate"/><link name="lidar"/>
  <joint name="a" type="fixed"><parent link="base"/><child link="plate"/>
    <origin xyz="0.1 0 0.2" rpy="{rpy}"/></joint>
  <joint name="b" type="fixed"><parent link="plate"/><child link="lidar"/>
    <origin xyz="0.05 0 0.01"/></joint>
</robot>"""


def test_the_chain_runs_from_a_link_up_to_the_root() -> None:
    urdf = ET.fromstring(ROBOT.format(rpy="0 0 1.5"))
    joints = joints_by_child(urdf)
    assert chain_to_root(joints, "lidar") == ["lidar", "plate", "base"]
    assert joint_origin(joints["plate"]) == ((0.1, 0.0, 0.2), (0.0, 0.0, 1.5))
    assert joint_origin(joints["lidar"]) == ((0.05, 0.0, 0.01), (0.0, 0.0, 0.0))


def test_a_loop_ends_the_walk() -> None:
    urdf = ET.fromstring(
        """<robot name="r"><link name="a"/><link name="b"/>
        <joint name="ab"><parent link="a"/><child link="b"/></joint>
        <joint name="ba"><parent link="b"/><child link="a"/></joint></robot>"""
    )
    assert len(chain_to_root(joints_by_child(urdf), "a")) <= 3


def test_a_bad_origin_is_refused_the_same_way_by_the_mount_and_the_live_view() -> None:
    """The live view read a malformed rpy as zeros and drew the LIDAR there, while the
    mount refused it: both now name the joint."""
    urdf = ET.fromstring(ROBOT.format(rpy="0 0"))
    with pytest.raises(ConfigError, match="joint 'a': rpy is not 3 numbers"):
        urdf_mount(urdf, "base", "lidar")
    with pytest.raises(ConfigError, match="joint 'a': rpy is not 3 numbers"):
        lidar_placement(urdf, "lidar")
