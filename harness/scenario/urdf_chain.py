"""A URDF's joints as a tree: each link's joint to its parent, the way to the root (pure).

The LIDAR's mount and the live view's LIDAR placement walk the same chain
and refuse the same bad input (a joint origin that is not three numbers).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from harness.errors import ConfigError
from harness.safe_text import shown

__all__ = ["chain_to_root", "joint_origin", "joints_by_child", "parent_link", "rpy_matrix"]

Triple = Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]


def joints_by_child(root: ET.Element) -> dict[str, ET.Element]:
    """Each child link's joint (the first, should a broken URDF name a child twice)."""
    joints: dict[str, ET.Element] = {}
    for joint in root.findall("joint"):
        child, parent = joint.find("child"), joint.find("parent")
        if child is not None and parent is not None:
            joints.setdefault(child.get("link", ""), joint)
    return joints


def parent_link(joint: ET.Element) -> str:
    parent = joint.find("parent")
    return parent.get("link", "") if parent is not None else ""


def chain_to_root(joints: dict[str, ET.Element], link: str) -> list[str]:
    """`link` and its ancestors up to the root (bounded: a loop ends it)."""
    chain = [link]
    while chain[-1] in joints and len(chain) <= len(joints):
        chain.append(parent_link(joints[chain[-1]]))
    return chain


def joint_origin(joint: ET.Element) -> tuple[Triple, Triple]:
    """(xyz, rpy) of a joint's child frame in its parent's; zeros where not given."""
    origin = joint.find("origin")
    return _triple(joint, origin, "xyz"), _triple(joint, origin, "rpy")


def _triple(joint: ET.Element, origin: ET.Element | None, name: str) -> Triple:
    text = (origin.get(name) if origin is not None else None) or "0 0 0"
    try:
        a, b, c = (float(v) for v in text.split())
    except ValueError:
        what = shown(joint.get("name", ""), 100)
        raise ConfigError(f"joint {what!r}: {name} is not 3 numbers") from None
    return a, b, c


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """URDF's fixed-axis roll, pitch, yaw as a rotation matrix (Rz @ Ry @ Rx)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return (
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    )
