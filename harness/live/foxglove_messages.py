"""The live view's messages: the world as a Foxglove scene, verdicts as JSON.

``foxglove`` is imported on first use (``sdk``): the harness works without
the ``live`` extra, and says which extra to install when a view is asked for.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from functools import cache
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from harness.errors import ConfigError
from harness.live.robot_mount import RobotShape
from harness.record.messages import verdict_fields
from harness.safe_text import shown
from harness.scenario.schema import Box, Cylinder, Model, Scenario, Wall

if TYPE_CHECKING:
    from harness.judge.oracle import Verdict


ODOM = "odom"  # the world frame, as /odom has it
BASE = "base_footprint"
INSTALL_HINT = "the live view needs foxglove-sdk: pip install 'fossbot-hil[live]'"


# The recordings' type names (harness.record.messages), here with JSON bodies.
STRING = "std_msgs/msg/String"
BOOL = "std_msgs/msg/Bool"
VERDICT = "fossbot_hil_msgs/msg/Verdict"

_NUMBER_OR_NULL = {"type": ["number", "null"]}
_TRISTATE = {"type": "integer", "enum": [1, 0, -1]}  # 1 True, 0 False, -1 either / none
SCHEMAS: dict[str, dict[str, Any]] = {
    STRING: {"data": {"type": "string"}},
    BOOL: {"data": {"type": "boolean"}},
    VERDICT: {  # the fields of harness.record.messages.VERDICT_DEFINITION, in its order
        "tick": {"type": "integer"}, "ok": {"type": "boolean"},
        "expected_obstacle": {"type": "boolean"}, "expected_distance": _NUMBER_OR_NULL,
        "expected_angle": _NUMBER_OR_NULL, "expected_warning": _TRISTATE,
        "claimed_obstacle": {"type": "boolean"}, "claimed_distance": _NUMBER_OR_NULL,
        "claimed_angle": _NUMBER_OR_NULL, "warning": _TRISTATE,
        "explanation": {"type": "string"},
    },
}  # fmt: skip

_OBSTACLE_RGBA = (0.8, 0.55, 0.3, 1.0)  # as harness.sim.world draws them
_MODEL_RGBA = (0.75, 0.3, 0.75, 0.8)  # a model file's place (its shape is not drawn)
_ROBOT_RGBA = (0.15, 0.35, 0.75, 0.6)  # the URDF's chassis blue, see-through


def nanoseconds(seconds: float) -> int:
    return max(0, round(seconds * 1e9)) if math.isfinite(seconds) else 0


def _finite(value: float | None) -> float | None:
    """JSON has no NaN or infinity (the app's parser refuses them): null instead."""
    return float(value) if value is not None and math.isfinite(value) else None


def verdict_message(verdict: Verdict) -> dict[str, Any]:
    """The recordings' Verdict fields as JSON: NaN becomes null, texts clipped."""
    return verdict_fields(verdict.clipped(), _finite)


def json_bytes(message: dict[str, Any]) -> bytes:
    return json.dumps(message, allow_nan=False, separators=(",", ":")).encode()


@cache
def foxglove_sdk() -> SimpleNamespace:
    """foxglove-sdk's modules, imported on first use; ConfigError naming the extra without it."""
    try:
        import foxglove
        import foxglove.channels
        import foxglove.messages
        import foxglove.websocket
    except ImportError:
        raise ConfigError(INSTALL_HINT) from None
    messages, channels, websocket = foxglove.messages, foxglove.channels, foxglove.websocket
    return SimpleNamespace(foxglove=foxglove, channels=channels, m=messages, websocket=websocket)


def sdk_stamp(seconds: float) -> Any:
    ns = nanoseconds(seconds)
    return foxglove_sdk().m.Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)


def pose_message(xyz: Iterable[float], quaternion: Iterable[float] = (0.0, 0.0, 0.0, 1.0)) -> Any:
    m = foxglove_sdk().m
    x, y, z = xyz
    qx, qy, qz, qw = quaternion
    return m.Pose(
        position=m.Vector3(x=x, y=y, z=z), orientation=m.Quaternion(x=qx, y=qy, z=qz, w=qw)
    )


def _color(rgba: tuple[float, float, float, float]) -> Any:
    return foxglove_sdk().m.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _cube(centre: Iterable[float], size: Iterable[float], yaw: float, rgba: Any) -> Any:
    sx, sy, sz = size
    m = foxglove_sdk().m
    return m.CubePrimitive(
        pose=pose_message(centre, yaw_quaternion(yaw)),
        size=m.Vector3(x=sx, y=sy, z=sz),
        color=_color(rgba),
    )


def _obstacle_parts(obstacle: Wall | Box | Cylinder | Model) -> dict[str, list[Any]]:
    """The primitives that draw one obstacle, as SceneEntity keyword arguments."""
    m = foxglove_sdk().m
    if isinstance(obstacle, Wall):
        (x0, y0), (x1, y1) = obstacle.start, obstacle.end
        centre = ((x0 + x1) / 2, (y0 + y1) / 2, obstacle.height / 2)
        size = (math.dist(obstacle.start, obstacle.end), obstacle.thickness, obstacle.height)
        return {"cubes": [_cube(centre, size, math.atan2(y1 - y0, x1 - x0), _OBSTACLE_RGBA)]}
    if isinstance(obstacle, Box):
        centre = (*obstacle.position, obstacle.size[2] / 2)
        return {"cubes": [_cube(centre, obstacle.size, obstacle.yaw, _OBSTACLE_RGBA)]}
    if isinstance(obstacle, Cylinder):
        diameter = 2 * obstacle.radius
        cylinder = m.CylinderPrimitive(
            pose=pose_message((*obstacle.position, obstacle.height / 2)),
            size=m.Vector3(x=diameter, y=diameter, z=obstacle.height),
            bottom_scale=1.0,
            top_scale=1.0,
            color=_color(_OBSTACLE_RGBA),
        )
        return {"cylinders": [cylinder]}
    x, y, z = obstacle.position  # a model file: its place and name, not its shape
    marker = m.SpherePrimitive(
        pose=pose_message((x, y, z + 0.05)),
        size=m.Vector3(x=0.1, y=0.1, z=0.1),
        color=_color(_MODEL_RGBA),
    )
    label = m.TextPrimitive(
        pose=pose_message((x, y, z + 0.2)),
        billboard=True,
        font_size=14.0,
        scale_invariant=True,
        color=_color((1.0, 1.0, 1.0, 1.0)),
        text=shown(obstacle.path, 80),
    )
    return {"spheres": [marker], "texts": [label]}


def _describe(obstacle: Wall | Box | Cylinder | Model) -> str:
    return f"model {shown(obstacle.path)}" if isinstance(obstacle, Model) else obstacle.describe()


def world_scene(scenario: Scenario, robot: RobotShape) -> Any:
    """The obstacles in ``odom`` (ids ``obstacles[i]`` as in the scenario file) and the robot."""
    m = foxglove_sdk().m
    entities = [
        m.SceneEntity(
            timestamp=sdk_stamp(0.0),
            frame_id=ODOM,
            id=f"obstacles[{index}]",
            metadata=[m.KeyValuePair(key="obstacle", value=_describe(obstacle))],
            **_obstacle_parts(obstacle),
        )
        for index, obstacle in enumerate(scenario.obstacles)
    ]
    if robot.body is not None:
        centre, size = robot.body
        body = _cube(centre, size, 0.0, _ROBOT_RGBA)
        entities.append(
            m.SceneEntity(
                timestamp=sdk_stamp(0.0), frame_id=BASE, id="robot", frame_locked=True, cubes=[body]
            )
        )
    return m.SceneUpdate(entities=entities)
