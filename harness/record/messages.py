"""The ROS 2 message types a recording holds, and CDR encoding without ROS.

rosbags' Jazzy type store supplies the standard types and their message
definitions (the MCAP schemas); the verdict is the one type of our own.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache
from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from harness.judge.oracle import Verdict
from harness.lidar.scan import Scan

LASER_SCAN = "sensor_msgs/msg/LaserScan"
CLOCK = "rosgraph_msgs/msg/Clock"
STRING = "std_msgs/msg/String"
BOOL = "std_msgs/msg/Bool"
POSE = "geometry_msgs/msg/PoseStamped"
VERDICT = "fossbot_hil_msgs/msg/Verdict"

VERDICT_DEFINITION = """\
# One tick as the fossbot-hil oracle judged it.
uint32 tick
bool ok
bool expected_obstacle
float64 expected_distance  # NaN when no obstacle is expected
float64 expected_angle  # NaN when no obstacle is expected
int8 expected_warning  # 1 True, 0 False, -1 either (inside the threshold band)
bool claimed_obstacle
float64 claimed_distance  # NaN when the status claimed none
float64 claimed_angle  # NaN when the status claimed none
int8 warning  # 1 True, 0 False, -1 none arrived
string explanation  # empty when ok
"""


@lru_cache(maxsize=1)
def typestore() -> Typestore:
    """The Jazzy types plus the verdict (built once; registering is slow)."""
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(VERDICT_DEFINITION, VERDICT))
    return store


def schema_text(msgtype: str) -> str:
    """The ros2msg definition MCAP stores as the schema (dependencies appended)."""
    text, _ = typestore().generate_msgdef(msgtype, ros_version=2)
    return text


def encode(message: Any, msgtype: str) -> bytes:
    return bytes(typestore().serialize_cdr(message, msgtype))


def _time(seconds: float) -> Any:
    store = typestore()
    sec = math.floor(seconds)
    nanosec = min(round((seconds - sec) * 1e9), 999_999_999)
    return store.types["builtin_interfaces/msg/Time"](sec=int(sec), nanosec=int(nanosec))


def _header(seconds: float, frame_id: str) -> Any:
    return typestore().types["std_msgs/msg/Header"](stamp=_time(seconds), frame_id=frame_id)


def laser_scan(scan: Scan) -> Any:
    return typestore().types[LASER_SCAN](
        header=_header(scan.stamp, scan.frame_id),
        angle_min=scan.angle_min,
        angle_max=scan.angle_max,
        angle_increment=scan.angle_increment,
        time_increment=scan.time_increment,
        scan_time=scan.scan_time,
        range_min=scan.range_min,
        range_max=scan.range_max,
        ranges=scan.ranges,
        intensities=scan.intensities,
    )


def clock(seconds: float) -> Any:
    return typestore().types[CLOCK](clock=_time(seconds))


def string(text: str) -> Any:
    return typestore().types[STRING](data=text)


def boolean(value: bool) -> Any:
    return typestore().types[BOOL](data=value)


def pose(seconds: float, x: float, y: float, yaw: float) -> Any:
    """The robot base in the world frame (planar: yaw about z)."""
    types = typestore().types
    position = types["geometry_msgs/msg/Point"](x=x, y=y, z=0.0)
    orientation = types["geometry_msgs/msg/Quaternion"](
        x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)
    )
    return types[POSE](
        header=_header(seconds, "world"),
        pose=types["geometry_msgs/msg/Pose"](position=position, orientation=orientation),
    )


def _tristate(value: bool | None) -> int:
    return -1 if value is None else int(value)


def _or_nan(value: float | None) -> float:
    return math.nan if value is None else float(value)


def verdict_fields(judged: Verdict, number: Callable[[float | None], Any]) -> dict[str, Any]:
    """The Verdict message's fields, `number` writing each float (None where none is)."""
    expected, claim = judged.expected, judged.claim
    return {
        "tick": judged.tick,
        "ok": judged.ok,
        "expected_obstacle": expected.obstacle,
        "expected_distance": number(expected.distance),
        "expected_angle": number(expected.angle),
        "expected_warning": _tristate(expected.warning),
        "claimed_obstacle": bool(claim and claim.obstacle),
        "claimed_distance": number(claim.distance if claim else None),
        "claimed_angle": number(claim.angle if claim else None),
        "warning": _tristate(judged.warning_got),
        "explanation": judged.explanation,
    }


def verdict(judged: Verdict) -> Any:
    return typestore().types[VERDICT](**verdict_fields(judged, _or_nan))


def planar_pose(message: Any) -> tuple[float, float, float]:
    """x, y and yaw of a recorded PoseStamped (the inverse of `pose`)."""
    q = message.pose.orientation
    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    return float(message.pose.position.x), float(message.pose.position.y), yaw
