"""Outlines on the floor (harness.scenario.footprint): pure geometry, and the FOSSBot's body."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import pytest

from harness.scenario.footprint import Outline, disc, overlap, rectangle, robot_outlines
from harness.scenario.model_files import robot_models_dir


def square(x: float, y: float, half: float = 0.5, yaw: float = 0.0, height: float = 1.0) -> Outline:
    return rectangle((x, y), half, half, yaw, height)


@pytest.mark.parametrize(
    ("a", "b", "depth"),
    [
        (square(0, 0), square(0.8, 0), 0.2),  # overlapping by 0.2 along x
        (square(0, 0), square(1.3, 0), -0.3),  # 0.3 apart
        (square(0, 0), disc((0.9, 0), 0.5, 1.0), 0.1),
        (square(0, 0), disc((0.9, 0.9), 0.5, 1.0), 0.5 - math.hypot(0.4, 0.4)),  # a corner
        (disc((0, 0), 1.0, 1.0), disc((1.5, 0), 0.7, 1.0), 0.2),
        (square(0, 0), square(0, 0, 0.1), 0.6),  # inside: the way out is 0.6
        (square(0, 0, yaw=math.pi / 4), square(1.0, 0), 0.5 * math.sqrt(2) - 0.5),
    ],
)
def test_overlap_depth(a: Outline, b: Outline, depth: float) -> None:
    """Penetration depth when overlapping, minus the distance when apart, either order."""
    assert overlap(a, b) == pytest.approx(depth)
    assert overlap(b, a) == pytest.approx(depth)


def test_far_apart_is_apart() -> None:
    """Far apart (their bounding boxes apart), the answer is negative, at most the gap."""
    assert -math.hypot(0.3, 0.4) <= overlap(square(0, 0), square(1.3, 1.4)) <= -0.4 + 1e-12


def test_overlap_counts_height() -> None:
    """A solid above another does not touch it; a shallow overlap in height is shallow."""
    low = square(0, 0, height=0.02)
    above = Outline(square(0, 0).points, 0.0, 0.025, 0.12)
    assert overlap(low, above) == pytest.approx(-0.005)
    assert overlap(square(0, 0, height=0.03), above) == pytest.approx(0.005)


def test_contains_is_depth_inside() -> None:
    """How deep a point lies inside an outline; negative outside."""
    assert square(0, 0).contains((0.1, 0)) == pytest.approx(0.4)
    assert square(0, 0).contains((0.7, 0)) == pytest.approx(-0.2)
    assert disc((0, 0), 1.0, 1.0).contains((0.6, 0.8)) == pytest.approx(0.0)


def test_fossbot_body_is_chassis_lidar_and_caster() -> None:
    """The FOSSBot's rigid body as robot_models/README.md sizes it; the wheels are left out."""
    root = ET.parse(robot_models_dir() / "fossbot_v2.urdf").getroot()
    parts = {o.label: o for o in robot_outlines(root)}
    assert sorted(parts) == [
        "link 'base_link' collision box",
        "link 'caster' collision sphere",
        "link 'lidar_link' collision box",
    ]
    chassis = parts["link 'base_link' collision box"]
    assert chassis.bounds() == pytest.approx((-0.12, -0.075, 0.06, 0.075))
    assert (chassis.z_low, chassis.z_high) == pytest.approx((0.025, 0.12))
    caster = parts["link 'caster' collision sphere"]
    assert caster.bounds() == pytest.approx((-0.11, -0.015, -0.08, 0.015))
    placed = chassis.placed(1.0, 2.0, math.pi / 2)  # turned left: forward is +y
    assert placed.bounds() == pytest.approx((0.925, 1.88, 1.075, 2.06))


def test_tilted_shapes_project_to_their_shadow() -> None:
    """A cylinder lying along y and a box turned about x: their extent seen from above."""
    root = ET.fromstring(
        '<robot name="r"><link name="base">'
        '<collision><origin xyz="0 0 0.1" rpy="1.5707963 0 0"/>'
        '<geometry><cylinder radius="0.1" length="0.4"/></geometry></collision>'
        '<collision><origin xyz="1 0 0.5" rpy="0.7853982 0 0"/>'
        '<geometry><box size="0.2 0.2 0.2"/></geometry></collision>'
        '<collision><geometry><mesh filename="x.stl"/></geometry></collision>'
        "</link></robot>"
    )
    lying, turned = robot_outlines(root)
    assert lying.bounds() == pytest.approx((-0.1, -0.2, 0.1, 0.2), abs=1e-6)
    assert (lying.z_low, lying.z_high) == pytest.approx((0.0, 0.2), abs=1e-6)
    half = 0.1 * math.sqrt(2)
    assert turned.bounds() == pytest.approx((0.9, -half, 1.1, half), abs=1e-6)
    assert (turned.z_low, turned.z_high) == pytest.approx((0.5 - half, 0.5 + half), abs=1e-6)
