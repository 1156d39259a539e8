"""Where the LIDAR device's zero points on the robot, as the robot model says (pure).

A URDF may carry a link for the device (``robot.lidar_device_link``): its
+x is the device's 0 degrees, its +z its top. Its orientation relative to
the scan link, through fixed joints only, is the mount: the yaw of its x,
mirrored when its z points down; a tilted device is refused (a spinning
LIDAR's plane is the scan plane). Without that link the mount is
``FORWARD`` while the field keeps its default (the value decides: a varied
scenario is rebuilt from its dumped fields); another link the URDF lacks is
a ``ConfigError``.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from harness.errors import ConfigError
from harness.lidar.mount import FORWARD, LidarMount
from harness.safe_text import shown
from harness.scenario.model_files import find_model_file, parse_xml, robot_models_dir
from harness.scenario.schema import DEFAULT_DEVICE_LINK, Scenario
from harness.scenario.urdf_chain import (
    chain_to_root,
    joint_origin,
    joints_by_child,
    parent_link,
    rpy_matrix,
)

__all__ = ["TILT_TOLERANCE_DEG", "lidar_mount", "scenario_mount", "urdf_mount"]

TILT_TOLERANCE_DEG = 1.0  # a device axis within this of the scan frame's z counts as parallel


@dataclass(frozen=True)
class _Reading:
    """What a URDF says about the mount: a mount, no device link (None), or a problem."""

    mount: LidarMount | None
    problem: str = ""


def _down_to(
    parents: dict[str, ET.Element], link: str, ancestor: str
) -> tuple[np.ndarray, str | None]:
    """Rotation of `link` in `ancestor`'s frame, and a moving joint on the way (if any)."""
    rotation, moving = np.eye(3), None
    while link != ancestor:
        joint = parents[link]
        rotation = np.array(rpy_matrix(*joint_origin(joint)[1])) @ rotation
        if joint.get("type") != "fixed":
            moving = f"{joint.get('type')} joint {joint.get('name')!r}"
        link = parent_link(joint)
    return rotation, moving


def urdf_mount(
    root: ET.Element, scan_link: str, device_link: str, *, model: str = "the URDF"
) -> LidarMount | None:
    """The mount of `device_link` relative to `scan_link`; None if the URDF has no such link.

    ConfigError naming the field and `model` when the scan link is missing, the
    device is tilted, or the two are not joined by fixed joints alone.
    """
    links = {link.get("name", "") for link in root.findall("link")}
    if device_link not in links:
        return None
    scan, device = repr(shown(scan_link, 100)), repr(shown(device_link, 100))
    if scan_link not in links:
        raise ConfigError(f"robot.lidar_link: no link named {scan} in {model}")
    parents = joints_by_child(root)
    what = f"robot.lidar_device_link: {device} in {model}"
    scan_chain = chain_to_root(parents, scan_link)
    device_chain = chain_to_root(parents, device_link)
    common = next((link for link in scan_chain if link in device_chain), None)
    if common is None:
        raise ConfigError(f"{what} is not joined to {scan}")
    scan_rotation, scan_moving = _down_to(parents, scan_link, common)
    device_rotation, device_moving = _down_to(parents, device_link, common)
    moving = device_moving or scan_moving
    if moving is not None:
        raise ConfigError(
            f"{what} is joined to {scan} through the {moving}; "
            "the device must be fixed to the scan link"
        )
    relative = scan_rotation.T @ device_rotation  # columns: the device's axes in the scan frame
    up = float(np.clip(relative[2, 2], -1.0, 1.0))
    tilt = math.degrees(math.acos(abs(up)))
    if tilt > TILT_TOLERANCE_DEG:
        raise ConfigError(
            f"{what} is tilted {tilt:.1f} deg from the z axis of {scan}; a spinning "
            "LIDAR's axis must be parallel to it (up, or down when mounted upside down)"
        )
    yaw = math.degrees(math.atan2(relative[1, 0], relative[0, 0]))
    yaw = round((yaw + 180.0) % 360.0 - 180.0, 9) + 0.0
    return LidarMount(yaw_deg=yaw, mirrored=up < 0.0)


@lru_cache(maxsize=32)
def _read(path: str, stamp: tuple[int, int], scan: str, device: str, model: str) -> _Reading:
    """`urdf_mount` of one file, cached per file version (`stamp`: mtime, size)."""
    root = parse_xml(Path(path), shown(path))
    try:
        return _Reading(urdf_mount(root, scan, device, model=model))
    except ConfigError as err:
        return _Reading(None, str(err))


def lidar_mount(scenario: Scenario, robot_urdf: Path) -> LidarMount:
    """The scenario's mount, read from `robot_urdf` (its robot, already found and checked)."""
    where = shown(scenario.source or "<scenario>")
    robot = scenario.robot
    model = repr(shown(robot.urdf, 100))
    try:
        info = os.stat(robot_urdf)
    except OSError as err:
        reason = err.strerror or type(err).__name__
        raise ConfigError(f"{where}: robot.urdf: cannot read {model}: {reason}") from None
    stamp = (info.st_mtime_ns, info.st_size)
    reading = _read(str(robot_urdf), stamp, robot.lidar_link, robot.lidar_device_link, model)
    if reading.problem:
        raise ConfigError(f"{where}: {reading.problem}")
    if reading.mount is not None:
        return reading.mount
    if robot.lidar_device_link != DEFAULT_DEVICE_LINK:
        raise ConfigError(
            f"{where}: robot.lidar_device_link: no link named "
            f"{shown(robot.lidar_device_link, 100)!r} in {model} (leave the field out for "
            "a generic mount, zero straight ahead)"
        )
    return FORWARD


def scenario_mount(scenario: Scenario) -> LidarMount:
    """How the scenario's LIDAR device sits on its robot: what its robot model says.

    The robot URDF is looked up as ``check_model_files`` does (the scenario's
    folder, then robot_models/); reading it is cached per file version.
    """
    where = shown(scenario.source or "<scenario>")
    ref = scenario.robot.urdf
    folders = [scenario.base_dir, robot_models_dir()]
    found = find_model_file(ref, folders, what=f"{where}: robot.urdf: cannot load {ref!r}")
    return lidar_mount(scenario, found.path)
