"""Where the LIDAR sits on the robot, and the robot's body box, from its URDF (pure).

The live view draws the scan in the LIDAR's frame, fixed on the robot
(``base_footprint``), where the URDF's joints put the scenario's
``robot.lidar_link``; a URDF that cannot be read leaves the LIDAR at the
robot's origin, and says why.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from harness.errors import ConfigError
from harness.safe_text import shown
from harness.scenario.footprint import robot_outlines
from harness.scenario.model_files import (
    check_model_file,
    find_model_file,
    parse_xml,
    robot_models_dir,
)
from harness.scenario.schema import Scenario
from harness.scenario.urdf_chain import chain_to_root, joint_origin, joints_by_child


@dataclass(frozen=True)
class Placement:
    """A frame in its parent frame: translation and unit quaternion (x, y, z, w)."""

    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quaternion: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def then(self, child: Placement) -> Placement:
        """`child` (given in this frame) in the frame this placement is given in."""
        moved = _rotate(self.quaternion, child.xyz)
        xyz = (self.xyz[0] + moved[0], self.xyz[1] + moved[1], self.xyz[2] + moved[2])
        return Placement(xyz, _multiply(self.quaternion, child.quaternion))


def _multiply(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _rotate(q: tuple[float, ...], v: tuple[float, float, float]) -> tuple[float, float, float]:
    x, y, z, _ = _multiply(_multiply(q, (*v, 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return x, y, z


def _rpy_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """URDF's fixed-axis roll, pitch, yaw (Rz @ Ry @ Rx) as a quaternion."""
    qx = (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2))
    qy = (0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2))
    qz = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    return _multiply(_multiply(qz, qy), qx)


def lidar_placement(urdf: ET.Element, link: str) -> Placement:
    """Where `link` sits in the URDF's root link (the robot's base_footprint), joints at zero."""
    if link not in {element.get("name") for element in urdf.findall("link")}:
        raise ConfigError(f"robot.lidar_link: no link named {shown(link)!r} in the robot's URDF")
    joints = joints_by_child(urdf)
    placement = Placement()
    for child in reversed(chain_to_root(joints, link)[:-1]):  # from the root down
        xyz, rpy = joint_origin(joints[child])
        placement = placement.then(Placement(xyz, _rpy_quaternion(*rpy)))
    return placement


def _body_box(urdf: ET.Element) -> tuple[tuple[float, float, float], tuple[float, ...]] | None:
    """Centre and size of the box around the robot's rigid body, in its root frame."""
    outlines = robot_outlines(urdf)
    if not outlines:
        return None
    corners = [o.bounds() for o in outlines]
    low = (min(c[0] for c in corners), min(c[1] for c in corners), min(o.z_low for o in outlines))
    high = (max(c[2] for c in corners), max(c[3] for c in corners), max(o.z_high for o in outlines))
    centre = ((low[0] + high[0]) / 2, (low[1] + high[1]) / 2, (low[2] + high[2]) / 2)
    return centre, tuple(h - lo for lo, h in zip(low, high, strict=True))


@dataclass(frozen=True)
class RobotShape:
    mount: Placement  # the LIDAR in base_footprint
    body: tuple[tuple[float, float, float], tuple[float, ...]] | None
    note: str = ""  # why the URDF was not used, if it was not


def robot_shape(scenario: Scenario) -> RobotShape:
    """The LIDAR's mounting and the body's box from the robot's URDF, or zeros and why."""
    what = f"robot.urdf: cannot load {scenario.robot.urdf!r}"
    try:
        folders = [scenario.base_dir, robot_models_dir()]
        found = find_model_file(scenario.robot.urdf, folders, what=what)
        check_model_file(found, what=what)
        urdf = parse_xml(found.path, what)
        return RobotShape(lidar_placement(urdf, scenario.robot.lidar_link), _body_box(urdf))
    except ConfigError as err:
        note = f"{err}; the live view draws the LIDAR at the robot's origin"
        return RobotShape(Placement(), None, note)
