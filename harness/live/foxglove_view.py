"""The live view: the world, the robot, its scan and the node's answers, in the Foxglove app.

``fossbot-hil sim`` serves its world over the Foxglove WebSocket protocol
with the official ``foxglove-sdk``, so a student watches it in the Foxglove
app with no ROS install. The simulator calls ``publish_pose``,
``publish_scan`` and ``publish_answer`` as it goes; this module only turns
them into Foxglove messages. Nothing is encoded for a channel no client
watches, so an unwatched view costs next to nothing.

Frames: ``odom`` (the scenario's world coordinates) -> ``base_footprint``
(the robot, from its pose) -> the LIDAR frame (fixed, where the robot's
URDF mounts the scenario's ``robot.lidar_link``). The answer topics and the
verdict carry the recordings' names and fields (JSON, ``{"data": ...}``),
so a layout made for a recording works live. The SDK keeps no message for
late clients, so the world's obstacles go out to each client as it
subscribes and again every ``WORLD_EVERY_S``.

``foxglove`` is imported when a view is made: the harness works without
the ``live`` extra. No rclpy, no pybullet.
"""

from __future__ import annotations

import errno
import json
import math
import re
import socket
import threading
import time
import weakref
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from types import SimpleNamespace, TracebackType
from typing import TYPE_CHECKING, Any

from harness.errors import ConfigError
from harness.safe_text import for_storage, shown
from harness.scenario.footprint import robot_outlines
from harness.scenario.model_files import (
    check_model_file,
    find_model_file,
    parse_xml,
    robot_models_dir,
)
from harness.scenario.schema import Box, Cylinder, Model, Scenario, Wall

if TYPE_CHECKING:
    from harness.judge.oracle import Verdict
    from harness.lidar.scan import Scan

__all__ = [
    "INSTALL_HINT",
    "FoxgloveView",
    "Placement",
    "ViewTopics",
    "lidar_placement",
    "verdict_message",
]

INSTALL_HINT = "the live view needs foxglove-sdk: pip install 'fossbot-hil[live]'"
ODOM = "odom"
BASE = "base_footprint"
WORLD_EVERY_S = 1.0  # wall-clock seconds between two sends of the world to watching clients
PORT_RELEASE_S = 2.0  # how long close() waits for the port to be free again

# The recordings' type names (harness.record.messages), here with JSON bodies.
STRING = "std_msgs/msg/String"
BOOL = "std_msgs/msg/Bool"
VERDICT = "fossbot_hil_msgs/msg/Verdict"

_NUMBER_OR_NULL = {"type": ["number", "null"]}
_TRISTATE = {"type": "integer", "enum": [1, 0, -1]}  # 1 True, 0 False, -1 either / none
_SCHEMAS: dict[str, dict[str, Any]] = {
    STRING: {"data": {"type": "string"}},
    BOOL: {"data": {"type": "boolean"}},
    VERDICT: {
        "tick": {"type": "integer"},
        "ok": {"type": "boolean"},
        "expected_obstacle": {"type": "boolean"},
        "expected_distance": _NUMBER_OR_NULL,
        "expected_angle": _NUMBER_OR_NULL,
        "expected_warning": _TRISTATE,
        "claimed_obstacle": {"type": "boolean"},
        "claimed_distance": _NUMBER_OR_NULL,
        "claimed_angle": _NUMBER_OR_NULL,
        "warning": _TRISTATE,
        "explanation": {"type": "string"},
    },
}

_OBSTACLE_RGBA = (0.8, 0.55, 0.3, 1.0)  # as harness.sim.world draws them
_MODEL_RGBA = (0.75, 0.3, 0.75, 0.8)  # a model file's place (its shape is not drawn)
_ROBOT_RGBA = (0.15, 0.35, 0.75, 0.6)  # the URDF's chassis blue, see-through


@dataclass(frozen=True)
class ViewTopics:
    """Where each stream goes; the answer topics are the lab's, as in the recordings."""

    scan: str = "/scan"
    tf: str = "/tf"
    pose: str = "/fossbot_hil/pose"
    status: str = "/lidar_status"
    warning: str = "/obstacle_warning"
    verdict: str = "/fossbot_hil/verdict"
    log: str = "/fossbot_hil/log"  # the judge's failures, for the Log panel
    world: str = "/world"


# -- geometry, pure ----------------------------------------------------------


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


def _three(text: str | None) -> tuple[float, float, float]:
    parts = (text or "").split()
    return (
        (float(parts[0]), float(parts[1]), float(parts[2])) if len(parts) == 3 else (0.0, 0.0, 0.0)
    )


def _joint_placement(joint: ET.Element) -> Placement:
    origin = joint.find("origin")
    if origin is None:
        return Placement()
    return Placement(_three(origin.get("xyz")), _rpy_quaternion(*_three(origin.get("rpy"))))


def lidar_placement(urdf: ET.Element, link: str) -> Placement:
    """Where `link` sits in the URDF's root link (the robot's base_footprint), joints at zero."""
    if link not in {element.get("name") for element in urdf.findall("link")}:
        raise ConfigError(f"robot.lidar_link: no link named {shown(link)!r} in the robot's URDF")
    joint_to = {
        child.get("link"): joint
        for joint in urdf.findall("joint")
        if (child := joint.find("child")) is not None
    }
    chain: list[ET.Element] = []
    name: str | None = link
    while name in joint_to and len(chain) < len(joint_to):  # a checked URDF is a tree
        chain.append(joint_to[name])
        parent = joint_to[name].find("parent")
        name = parent.get("link") if parent is not None else None
    placement = Placement()
    for joint in reversed(chain):
        placement = placement.then(_joint_placement(joint))
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
class _Robot:
    mount: Placement  # the LIDAR in base_footprint
    body: tuple[tuple[float, float, float], tuple[float, ...]] | None
    note: str = ""  # why the URDF was not used, if it was not


def _robot(scenario: Scenario) -> _Robot:
    """The LIDAR's mounting and the body's box from the robot's URDF, or zeros and why."""
    what = f"robot.urdf: cannot load {scenario.robot.urdf!r}"
    try:
        folders = [scenario.base_dir, robot_models_dir()]
        found = find_model_file(scenario.robot.urdf, folders, what=what)
        check_model_file(found, what=what)
        urdf = parse_xml(found.path, what)
        return _Robot(lidar_placement(urdf, scenario.robot.lidar_link), _body_box(urdf))
    except ConfigError as err:
        note = f"{err}; the live view draws the LIDAR at the robot's origin"
        return _Robot(Placement(), None, note)


# -- messages ----------------------------------------------------------------


def _ns(seconds: float) -> int:
    return max(0, round(seconds * 1e9)) if math.isfinite(seconds) else 0


def _finite(value: float | None) -> float | None:
    """JSON has no NaN or infinity (the app's parser refuses them): null instead."""
    return float(value) if value is not None and math.isfinite(value) else None


def _tristate(value: bool | None) -> int:
    return -1 if value is None else int(value)


def verdict_message(verdict: Verdict) -> dict[str, Any]:
    """The recordings' Verdict fields as JSON: NaN becomes null, texts clipped."""
    kept = verdict.clipped()
    expected, claim = kept.expected, kept.claim
    return {
        "tick": kept.tick,
        "ok": kept.ok,
        "expected_obstacle": expected.obstacle,
        "expected_distance": _finite(expected.distance),
        "expected_angle": _finite(expected.angle),
        "expected_warning": _tristate(expected.warning),
        "claimed_obstacle": bool(claim and claim.obstacle),
        "claimed_distance": _finite(claim.distance if claim else None),
        "claimed_angle": _finite(claim.angle if claim else None),
        "warning": _tristate(kept.warning_got),
        "explanation": kept.explanation,
    }


def _json(message: dict[str, Any]) -> bytes:
    return json.dumps(message, allow_nan=False, separators=(",", ":")).encode()


@cache
def _sdk() -> SimpleNamespace:
    """foxglove-sdk's modules, imported on first use; ConfigError naming the extra without it."""
    try:
        import foxglove
        import foxglove.channels
        import foxglove.messages
        import foxglove.websocket
    except ImportError:
        raise ConfigError(INSTALL_HINT) from None
    return SimpleNamespace(
        foxglove=foxglove,
        channels=foxglove.channels,
        m=foxglove.messages,
        websocket=foxglove.websocket,
    )


def _stamp(seconds: float) -> Any:
    ns = _ns(seconds)
    return _sdk().m.Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)


def _pose(xyz: Iterable[float], quaternion: Iterable[float] = (0.0, 0.0, 0.0, 1.0)) -> Any:
    m = _sdk().m
    x, y, z = xyz
    qx, qy, qz, qw = quaternion
    return m.Pose(
        position=m.Vector3(x=x, y=y, z=z), orientation=m.Quaternion(x=qx, y=qy, z=qz, w=qw)
    )


def _color(rgba: tuple[float, float, float, float]) -> Any:
    return _sdk().m.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def _yaw(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _cube(centre: Iterable[float], size: Iterable[float], yaw: float, rgba: Any) -> Any:
    sx, sy, sz = size
    m = _sdk().m
    return m.CubePrimitive(
        pose=_pose(centre, _yaw(yaw)), size=m.Vector3(x=sx, y=sy, z=sz), color=_color(rgba)
    )


def _obstacle_parts(obstacle: Wall | Box | Cylinder | Model) -> dict[str, list[Any]]:
    """The primitives that draw one obstacle, as SceneEntity keyword arguments."""
    m = _sdk().m
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
            pose=_pose((*obstacle.position, obstacle.height / 2)),
            size=m.Vector3(x=diameter, y=diameter, z=obstacle.height),
            bottom_scale=1.0,
            top_scale=1.0,
            color=_color(_OBSTACLE_RGBA),
        )
        return {"cylinders": [cylinder]}
    x, y, z = obstacle.position  # a model file: its place and name, not its shape
    marker = m.SpherePrimitive(
        pose=_pose((x, y, z + 0.05)), size=m.Vector3(x=0.1, y=0.1, z=0.1), color=_color(_MODEL_RGBA)
    )
    label = m.TextPrimitive(
        pose=_pose((x, y, z + 0.2)),
        billboard=True,
        font_size=14.0,
        scale_invariant=True,
        color=_color((1.0, 1.0, 1.0, 1.0)),
        text=shown(obstacle.path, 80),
    )
    return {"spheres": [marker], "texts": [label]}


def _describe(obstacle: Wall | Box | Cylinder | Model) -> str:
    return f"model {shown(obstacle.path)}" if isinstance(obstacle, Model) else obstacle.describe()


def world_scene(scenario: Scenario, robot: _Robot) -> Any:
    """The obstacles in ``odom`` (ids ``obstacles[i]`` as in the scenario file) and the robot."""
    m = _sdk().m
    entities = [
        m.SceneEntity(
            timestamp=_stamp(0.0),
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
                timestamp=_stamp(0.0), frame_id=BASE, id="robot", frame_locked=True, cubes=[body]
            )
        )
    return m.SceneUpdate(entities=entities)


# -- the server ----------------------------------------------------------------


def _check_address(host: str, port: int) -> None:
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ConfigError(f"live view port {port!r}: must be a whole number from 0 to 65535")
    if not isinstance(host, str) or not host.strip():
        raise ConfigError(f"live view host {host!r}: must name an address to listen on")


def _bind_problem(host: str, port: int, err: BaseException) -> str:
    """The SDK's failure to listen (``FoxgloveError: Failed to bind port: ...``) as one line."""
    text = re.sub(r"^(FoxgloveError:\s*)?(Failed to bind port:\s*)?", "", str(err).strip())
    code = re.search(r"\(os error (\d+)\)", text)
    reason = re.sub(r"\s*\(os error \d+\)", "", text) or type(err).__name__
    hint = ""
    if code and int(code.group(1)) == errno.EADDRINUSE:
        hint = " (another fossbot-hil sim or a Foxglove bridge? choose another port)"
    elif code and int(code.group(1)) == errno.EACCES:
        hint = " (ports below 1024 need privileges; choose another port)"
    return shown(f"the live view cannot listen on {host}:{port}: {reason.lower()}{hint}", 300)


def _wait_released(host: str, port: int, within: float) -> None:
    """Until the SDK's listener has really closed (it closes asynchronously), at most `within`.

    A bind with SO_REUSEADDR fails only while something listens on the port.
    """
    try:
        family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    except OSError:
        return
    deadline = time.monotonic() + within
    while True:
        with socket.socket(family, kind, proto) as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind(address)
                return
            except OSError:
                pass
        if time.monotonic() >= deadline:
            return
        time.sleep(0.002)


def _listener(view: FoxgloveView) -> Any:
    """A ServerListener telling `view` (held weakly) of subscriptions, on the SDK's thread."""
    ref = weakref.ref(view)

    class Listener(_sdk().websocket.ServerListener):  # type: ignore[misc]
        def on_subscribe(self, client: Any, channel: Any) -> None:
            target = ref()
            if target is not None:
                target._subscribed(channel.topic, +1)

        def on_unsubscribe(self, client: Any, channel: Any) -> None:
            target = ref()
            if target is not None:
                target._subscribed(channel.topic, -1)

    return Listener()


class FoxgloveView:
    """A Foxglove WebSocket server showing one scenario's world live; close() it when done."""

    def __init__(
        self,
        scenario: Scenario,
        *,
        host: str = "127.0.0.1",
        port: int = 8765,
        topics: ViewTopics = ViewTopics(),
    ) -> None:
        _check_address(host, port)
        sdk = _sdk()
        self.topics = topics
        self.host = host
        self._closed = False
        self._watching: dict[str, int] = {}
        self._changed = threading.Condition()
        self._robot = _robot(scenario)
        self.notes = [self._robot.note] if self._robot.note else []
        self._lidar_frame = scenario.robot.lidar_link
        self._scene = world_scene(scenario, self._robot)
        self._world_sent = -math.inf
        self._now_ns = 0  # the latest simulation time published, for the world's log time
        self._context = sdk.foxglove.Context()
        self._channels = self._advertise(sdk)
        name = f"fossbot-hil sim: {shown(scenario.name or scenario.description, 80)}"
        try:
            self._server = sdk.foxglove.start_server(
                name=name,
                host=host,
                port=port,
                capabilities=[sdk.websocket.Capability.Time],
                server_listener=_listener(self),
                context=self._context,
            )
        except (RuntimeError, OverflowError, ValueError) as err:
            self._close_channels()
            raise ConfigError(_bind_problem(host, port, err)) from None
        self.port: int = self._server.port

    def _advertise(self, sdk: SimpleNamespace) -> dict[str, Any]:
        """The view's channels, on this view's own context (two views never share one)."""
        t, ch, context = self.topics, sdk.channels, self._context
        channels = {
            "scan": ch.LaserScanChannel(t.scan, context=context),
            "tf": ch.FrameTransformsChannel(t.tf, context=context),
            "pose": ch.PoseInFrameChannel(t.pose, context=context),
            "world": ch.SceneUpdateChannel(t.world, context=context),
            "log": ch.LogChannel(t.log, context=context),
        }
        for key, topic, name in (
            ("status", t.status, STRING),
            ("warning", t.warning, BOOL),
            ("verdict", t.verdict, VERDICT),
        ):
            schema = {"type": "object", "properties": _SCHEMAS[name]}
            channels[key] = sdk.foxglove.Channel(
                topic,
                schema=sdk.foxglove.Schema(
                    name=name, encoding="jsonschema", data=json.dumps(schema).encode()
                ),
                message_encoding="json",
                context=context,
            )
        return channels

    # -- what the simulator calls ------------------------------------------------

    def publish_pose(self, t: float, x: float, y: float, yaw: float) -> None:
        """The robot at simulation time `t`: the server's clock, /tf and the pose channel."""
        if self._closed:
            return
        ns = self._now_ns = _ns(t)
        self._server.broadcast_time(ns)  # the app's "now" is simulation time, as with sim time
        if self._channels["tf"].has_sinks():
            self._channels["tf"].log(self._transforms(t, x, y, yaw), log_time=ns)
        if self._channels["pose"].has_sinks():
            pose = _sdk().m.PoseInFrame(
                timestamp=_stamp(t), frame_id=ODOM, pose=_pose((x, y, 0.0), _yaw(yaw))
            )
            self._channels["pose"].log(pose, log_time=ns)
        if time.monotonic() - self._world_sent >= WORLD_EVERY_S:
            self._send_world(ns)

    def publish_scan(self, t: float, scan: Scan) -> None:
        """One revolution as the node received it, in the LIDAR frame, stamped as the scan."""
        self._lidar_frame = scan.frame_id  # the scan names the frame; the URDF places it
        channel = self._channels["scan"]
        if self._closed or not channel.has_sinks():
            return
        beams = scan.ranges.size
        message = _sdk().m.LaserScan(
            timestamp=_stamp(scan.stamp),
            frame_id=scan.frame_id,
            pose=_pose((0.0, 0.0, 0.0)),
            start_angle=scan.angle_min,
            end_angle=scan.angle_min + max(beams - 1, 0) * scan.angle_increment,
            ranges=scan.ranges.tolist(),
            intensities=scan.intensities.tolist() if scan.intensities.size == beams else [],
        )
        channel.log(message, log_time=_ns(t))

    def publish_answer(
        self,
        t: float,
        status: str | None,
        warning: bool | None,
        verdict: Verdict | None = None,
    ) -> None:
        """What the node said (None: nothing new) and how the live judge found a tick."""
        if self._closed:
            return
        ns = _ns(t)
        if status is not None:
            self._log_json("status", {"data": for_storage(str(status))}, ns)
        if warning is not None:
            self._log_json("warning", {"data": bool(warning)}, ns)
        if verdict is not None:
            self._log_json("verdict", verdict_message(verdict), ns)
            if not verdict.ok and self._channels["log"].has_sinks():
                self._channels["log"].log(self._failure_log(t, verdict), log_time=ns)

    # -- who watches ---------------------------------------------------------------

    def watched(self) -> set[str]:
        """The topics some client subscribes to now."""
        with self._changed:
            return {topic for topic, count in self._watching.items() if count > 0}

    def wait_for_subscribers(self, topics: Iterable[str], timeout: float) -> bool:
        """Whether every topic in `topics` gets a subscriber within `timeout` seconds."""
        wanted = set(topics)

        def all_watched() -> bool:
            return all(self._watching.get(topic, 0) > 0 for topic in wanted)

        with self._changed:
            return self._changed.wait_for(all_watched, timeout)

    def _subscribed(self, topic: str, change: int) -> None:
        """The SDK's listener: a client (un)subscribed; a new watcher of the world gets it now."""
        with self._changed:
            self._watching[topic] = max(0, self._watching.get(topic, 0) + change)
            self._changed.notify_all()
        if change > 0 and topic == self.topics.world and not self._closed:
            self._channels["world"].log(self._scene, log_time=self._now_ns)

    # -- helpers --------------------------------------------------------------------

    def _transforms(self, t: float, x: float, y: float, yaw: float) -> Any:
        """odom -> base_footprint from the pose, and the fixed base_footprint -> LIDAR."""
        m, stamp = _sdk().m, _stamp(t)
        mount = self._robot.mount
        return m.FrameTransforms(
            transforms=[
                m.FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=ODOM,
                    child_frame_id=BASE,
                    translation=m.Vector3(x=x, y=y, z=0.0),
                    rotation=m.Quaternion(z=math.sin(yaw / 2), w=math.cos(yaw / 2)),
                ),
                m.FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=BASE,
                    child_frame_id=self._lidar_frame,
                    translation=m.Vector3(x=mount.xyz[0], y=mount.xyz[1], z=mount.xyz[2]),
                    rotation=m.Quaternion(**dict(zip("xyzw", mount.quaternion, strict=True))),
                ),
            ]
        )

    def _send_world(self, ns: int) -> None:
        self._world_sent = time.monotonic()
        if self._channels["world"].has_sinks():
            self._channels["world"].log(self._scene, log_time=ns)

    def _log_json(self, key: str, message: dict[str, Any], ns: int) -> None:
        channel = self._channels[key]
        if channel.has_sinks():
            channel.log(_json(message), log_time=ns)

    def _failure_log(self, t: float, verdict: Verdict) -> Any:
        m = _sdk().m
        return m.Log(
            timestamp=_stamp(t),
            level=m.LogLevel.Warning,
            message=f"tick {verdict.tick}: {verdict.clipped().explanation}",
            name="fossbot-hil judge",
        )

    # -- the end ----------------------------------------------------------------------

    @property
    def url(self) -> str:
        """The WebSocket address to open in the Foxglove app."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    @property
    def app_url(self) -> str | None:
        """A link that opens this server in the Foxglove web app (None once closed)."""
        return None if self._closed else self._server.app_url()

    @property
    def closed(self) -> bool:
        return self._closed

    def close(self) -> None:
        """Stop serving; the port is free again when this returns. Calling it again does nothing."""
        if self._closed:
            return
        self._closed = True
        self._close_channels()
        self._server.stop()
        _wait_released(self.host, self.port, PORT_RELEASE_S)

    def _close_channels(self) -> None:
        for channel in self._channels.values():
            channel.close()

    def __enter__(self) -> FoxgloveView:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
