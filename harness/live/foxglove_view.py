"""The live view: the world, the robot, its scan and the node's answers, in the Foxglove app.

Served with the official ``foxglove-sdk``, so a student watches with no ROS
install. Nothing is encoded for a channel no client watches, so an
unwatched view costs next to nothing. Frames: ``odom`` -> ``base_footprint``
-> the LIDAR frame (where the URDF mounts it). Answers and verdicts carry
the recordings' topics and fields, so a layout made for a recording works
live. The SDK keeps nothing for late clients, so the world goes to each
client as it subscribes and again every ``WORLD_EVERY_S``. No rclpy, no pybullet.
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
from collections.abc import Iterable
from dataclasses import dataclass
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from harness.errors import ConfigError
from harness.live.foxglove_messages import (
    BASE,
    BOOL,
    ODOM,
    SCHEMAS,
    STRING,
    VERDICT,
    foxglove_sdk,
    json_bytes,
    nanoseconds,
    pose_message,
    sdk_stamp,
    verdict_message,
    world_scene,
    yaw_quaternion,
)
from harness.live.robot_mount import robot_shape
from harness.record.writer import RecordTopics
from harness.safe_text import for_storage, shown
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.judge.oracle import Verdict
    from harness.lidar.scan import Scan


WORLD_EVERY_S = 1.0  # wall-clock seconds between two sends of the world to watching clients
PORT_RELEASE_S = 2.0  # how long close() waits for the port to be free again


_RECORDED = RecordTopics()


@dataclass(frozen=True)
class ViewTopics:
    """Where each stream goes: the recordings' topics (a layout made for one works live),
    and the view's own frames, log and world."""

    scan: str = _RECORDED.scan
    tf: str = "/tf"
    pose: str = _RECORDED.pose
    status: str = _RECORDED.status
    warning: str = _RECORDED.warning
    verdict: str = _RECORDED.verdict
    log: str = "/fossbot_hil/log"  # the judge's failures, for the Log panel
    world: str = "/world"


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
    """Until the SDK's listener (closed asynchronously) is gone, at most `within`: a bind
    with SO_REUSEADDR fails only while something listens on the port."""
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

    class Listener(foxglove_sdk().websocket.ServerListener):  # type: ignore[misc]
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
        sdk = foxglove_sdk()
        self.topics = topics
        self.host = host
        self._closed = False
        self._watching: dict[str, int] = {}
        self._changed = threading.Condition()
        self._robot = robot_shape(scenario)
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
            schema = {"type": "object", "properties": SCHEMAS[name]}
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
        ns = self._now_ns = nanoseconds(t)
        self._server.broadcast_time(ns)  # the app's "now" is simulation time, as with sim time
        if self._channels["tf"].has_sinks():
            self._channels["tf"].log(self._transforms(t, x, y, yaw), log_time=ns)
        if self._channels["pose"].has_sinks():
            pose = foxglove_sdk().m.PoseInFrame(
                timestamp=sdk_stamp(t),
                frame_id=ODOM,
                pose=pose_message((x, y, 0.0), yaw_quaternion(yaw)),
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
        message = foxglove_sdk().m.LaserScan(
            timestamp=sdk_stamp(scan.stamp),
            frame_id=scan.frame_id,
            pose=pose_message((0.0, 0.0, 0.0)),
            start_angle=scan.angle_min,
            end_angle=scan.angle_min + max(beams - 1, 0) * scan.angle_increment,
            ranges=scan.ranges.tolist(),
            intensities=scan.intensities.tolist() if scan.intensities.size == beams else [],
        )
        channel.log(message, log_time=nanoseconds(t))

    def publish_answer(
        self, t: float, status: str | None, warning: bool | None, verdict: Verdict | None = None
    ) -> None:
        """What the node said (None: nothing new) and how the live judge found a tick."""
        if self._closed:
            return
        ns = nanoseconds(t)
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
        m, stamp = foxglove_sdk().m, sdk_stamp(t)
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
            channel.log(json_bytes(message), log_time=ns)

    def _failure_log(self, t: float, verdict: Verdict) -> Any:
        m = foxglove_sdk().m
        return m.Log(
            timestamp=sdk_stamp(t),
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

    def __exit__(self, *exc: object) -> None:
        self.close()
