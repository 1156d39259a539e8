"""The live view, proven with a real Foxglove WebSocket client (the `websockets` package).

The client speaks the Foxglove WebSocket protocol as the app does: the
handshake's subprotocol, serverInfo and advertise (JSON), subscribe, then
binary messageData frames (opcode 0x01, subscription id, log time, payload).
foxglove-sdk 0.30 names the protocol ``foxglove.sdk.v1`` in the handshake
(``foxglove.websocket.v1`` before it; the frames are the same). Protobuf
payloads are read with a small wire-format reader below, so what is checked
is what a client receives, not what the SDK says it sent.
"""

from __future__ import annotations

import asyncio
import json
import math
import socket
import struct
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
import websockets

from harness.errors import ConfigError
from harness.judge.oracle import Expectation, Verdict
from harness.judge.status import StatusClaim
from harness.lidar.scan import Scan
from harness.live import foxglove_messages
from harness.live.foxglove_messages import INSTALL_HINT, verdict_message
from harness.live.foxglove_view import FoxgloveView
from harness.live.robot_mount import Placement, lidar_placement
from harness.safe_text import TEXT_LIMIT
from harness.scenario.schema import Scenario

SUBPROTOCOL = "foxglove.sdk.v1"
WAIT_S = 5.0  # every wait on the server is bounded by this

PROTOBUF = {
    "/scan": "foxglove.LaserScan",
    "/tf": "foxglove.FrameTransforms",
    "/fossbot_hil/pose": "foxglove.PoseInFrame",
    "/world": "foxglove.SceneUpdate",
    "/fossbot_hil/log": "foxglove.Log",
}
JSON = {
    "/lidar_status": "std_msgs/msg/String",
    "/obstacle_warning": "std_msgs/msg/Bool",
    "/fossbot_hil/verdict": "fossbot_hil_msgs/msg/Verdict",
}
MOUNT = (-0.016, 0.0, 0.155)  # fossbot_v2.urdf: lidar_scan_frame in base_footprint


def scenario(**robot: Any) -> Scenario:
    return Scenario.model_validate(
        {
            "name": "view_test",
            "description": "one of each obstacle",
            "robot": robot,
            "obstacles": [
                {"type": "wall", "start": [2.0, -2.0], "end": [2.0, 2.0], "thickness": 0.1},
                {"type": "box", "position": [1.0, 1.0], "size": [0.2, 0.3, 0.4], "yaw": 0.5},
                {"type": "cylinder", "position": [-1.0, 0.0], "radius": 0.2},
                {"type": "model", "path": "table.urdf", "position": [0.0, -1.5, 0.0]},
            ],
            "motion": {"segments": [{"until": {"duration": 1.0}}]},
        }
    )


def a_scan(t: float, beams: int = 360) -> Scan:
    increment = 2 * math.pi / beams
    ranges = np.linspace(0.5, 3.0, beams, dtype=np.float32)
    ranges[7] = np.inf  # REP-117 "no return": sent as it is
    return Scan(-math.pi, math.pi - increment, increment, 0.0, 0.1, 0.12, 12.0, ranges, stamp=t)


def a_failure(t: float) -> Verdict:
    claim = StatusClaim("Obstacle at 9.00 m", True, 9.0, None, 2, None)
    expected = Expectation(True, 0.5, -math.pi, 0, True)
    return Verdict(7, t, False, expected, claim, None, ("distance",), "expected 0.50 m, got 9.00")


# -- the protobuf wire format, enough to read what the view sends -------------


def _varint(buf: bytes, i: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        byte = buf[i]
        i += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, i


def fields(buf: bytes) -> dict[int, list[Any]]:
    """Field number -> values (varint int, fixed64 double, or bytes) of one message."""
    out: dict[int, list[Any]] = {}
    i = 0
    while i < len(buf):
        key, i = _varint(buf, i)
        kind = key & 7
        if kind == 0:
            value, i = _varint(buf, i)
        elif kind == 1:
            value, i = struct.unpack_from("<d", buf, i)[0], i + 8
        elif kind == 2:
            size, i = _varint(buf, i)
            value, i = bytes(buf[i : i + size]), i + size
        else:
            raise AssertionError(f"unexpected wire type {kind}")
        out.setdefault(key >> 3, []).append(value)
    return out


def vector(buf: bytes, count: int = 3) -> tuple[float, ...]:
    """A Vector3 / Quaternion (absent fields are 0, as protobuf omits defaults)."""
    f = fields(buf)
    return tuple(f.get(n, [0.0])[0] for n in range(1, count + 1))


def text(message: dict[int, list[Any]], number: int) -> str:
    return message.get(number, [b""])[0].decode()


# -- a Foxglove WebSocket client -------------------------------------------------


@dataclass
class Received:
    topic: str
    log_time: int
    payload: bytes


@dataclass
class Client:
    """One connection, as the Foxglove app makes it."""

    ws: Any
    info: dict[str, Any] = field(default_factory=dict)
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)  # topic -> advertised
    topic_of: dict[int, str] = field(default_factory=dict)  # subscription id -> topic
    times: list[int] = field(default_factory=list)  # the server's clock (opcode 0x02)

    async def hello(self, topics: set[str]) -> None:
        """serverInfo, then advertise messages until every one of `topics` is advertised."""
        self.info = json.loads(await asyncio.wait_for(self.ws.recv(), WAIT_S))
        assert self.info["op"] == "serverInfo"
        while not topics <= set(self.channels):
            message = json.loads(await asyncio.wait_for(self.ws.recv(), WAIT_S))
            if message["op"] == "advertise":
                self.channels.update({c["topic"]: c for c in message["channels"]})

    async def subscribe(self, topics: list[str]) -> None:
        first = len(self.topic_of) + 1
        subscriptions = [
            {"id": first + n, "channelId": self.channels[topic]["id"]}
            for n, topic in enumerate(topics)
        ]
        self.topic_of.update({first + n: topic for n, topic in enumerate(topics)})
        await self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subscriptions}))

    async def data(self) -> Received:
        """The next messageData frame (the clock's frames are noted on the way)."""
        while True:
            frame = await asyncio.wait_for(self.ws.recv(), WAIT_S)
            if isinstance(frame, str):
                continue  # e.g. a later advertise
            if frame[0] == 0x02:
                self.times.append(struct.unpack_from("<Q", frame, 1)[0])
                continue
            assert frame[0] == 0x01, f"opcode {frame[0]:#x}"
            subscription, log_time = struct.unpack_from("<IQ", frame, 1)
            return Received(self.topic_of[subscription], log_time, frame[13:])

    async def clock_reaches(self, ns: int) -> None:
        """Read on until the server's clock frame for `ns` arrived: the SDK sends it on its
        own path, so it may come after the messages logged at that time."""
        while ns not in self.times:
            frame = await asyncio.wait_for(self.ws.recv(), WAIT_S)
            if isinstance(frame, bytes) and frame[0] == 0x02:
                self.times.append(struct.unpack_from("<Q", frame, 1)[0])

    async def until(self, topics: set[str]) -> dict[str, Received]:
        """The first message on each of `topics` (others are kept too, the newest)."""
        got: dict[str, Received] = {}
        while not topics <= set(got):
            message = await self.data()
            got[message.topic] = message
        return got


async def connect(port: int, topics: set[str]) -> Client:
    ws = await asyncio.wait_for(
        websockets.connect(f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL]), WAIT_S
    )
    assert ws.subprotocol == SUBPROTOCOL
    client = Client(ws)
    await client.hello(topics)
    return client


async def subscribed(view: FoxgloveView, topics: set[str]) -> None:
    """The SDK's listener told the view each topic has a subscriber."""
    assert await asyncio.to_thread(view.wait_for_subscribers, topics, WAIT_S), view.watched()


@pytest.fixture
def view() -> Iterator[FoxgloveView]:
    with FoxgloveView(scenario(), port=0) as serving:
        yield serving


def _ns(seconds: float) -> int:
    return round(seconds * 1e9)


# -- advertise and subscribe ---------------------------------------------------------


def test_advertises_every_topic_with_its_schema(view: FoxgloveView) -> None:
    async def run() -> Client:
        client = await connect(view.port, set(PROTOBUF) | set(JSON))
        await client.ws.close()
        return client

    client = asyncio.run(run())
    assert view.url == f"ws://127.0.0.1:{view.port}"
    assert view.app_url is not None and f"127.0.0.1%3A{view.port}" in view.app_url
    assert client.info["name"] == "fossbot-hil sim: view_test"
    assert "time" in client.info["capabilities"]  # the app's clock is simulation time
    for topic, schema in PROTOBUF.items():
        channel = client.channels[topic]
        assert (channel["schemaName"], channel["encoding"]) == (schema, "protobuf"), topic
    for topic, schema in JSON.items():
        channel = client.channels[topic]
        assert (channel["schemaName"], channel["encoding"]) == (schema, "json"), topic
        assert channel["schemaEncoding"] == "jsonschema"
        assert json.loads(channel["schema"])["type"] == "object"
    status = json.loads(client.channels["/lidar_status"]["schema"])
    assert status["properties"]["data"] == {"type": "string"}


def test_subscribed_client_gets_pose_scan_answers_and_world(view: FoxgloveView) -> None:
    every = set(PROTOBUF) | set(JSON)
    t = 1.25
    long_status = "Obstacle at 0.50 m\x1b[2J" + "x" * 10_000

    async def run() -> tuple[Client, dict[str, Received]]:
        client = await connect(view.port, every)
        await client.subscribe(sorted(every))
        await subscribed(view, every)
        world = await client.until({"/world"})  # on subscribing, before anything is published
        view.publish_pose(t, 1.0, 2.0, math.pi / 2)
        view.publish_scan(t, a_scan(t))
        view.publish_answer(t, long_status, True, a_failure(t))
        got = await client.until(every - {"/world"})
        await client.clock_reaches(_ns(t))  # bounded: WAIT_S per frame
        await client.ws.close()
        return client, world | got

    client, got = asyncio.run(run())
    assert {m.log_time for topic, m in got.items() if topic != "/world"} == {_ns(t)}
    _check_world(fields(got["/world"].payload))
    _check_transforms(fields(got["/tf"].payload), t)
    _check_scan(fields(got["/scan"].payload), a_scan(t), t)
    pose = fields(got["/fossbot_hil/pose"].payload)
    assert text(pose, 2) == "odom"
    status = json.loads(got["/lidar_status"].payload)["data"]
    assert status.startswith("Obstacle at 0.50 m\x1b[2J") and len(status) <= TEXT_LIMIT
    assert f"{len(long_status)} characters" in status  # clipped, and says so
    assert json.loads(got["/obstacle_warning"].payload) == {"data": True}
    verdict = json.loads(got["/fossbot_hil/verdict"].payload)
    assert verdict == verdict_message(a_failure(t))
    assert (verdict["ok"], verdict["claimed_angle"], verdict["warning"]) == (False, None, -1)
    log = fields(got["/fossbot_hil/log"].payload)
    assert text(log, 3) == "tick 7: expected 0.50 m, got 9.00" and log[2] == [3]  # WARNING


def _check_world(update: dict[int, list[Any]]) -> None:
    entities = [fields(e) for e in update[2]]
    ids = [text(e, 3) for e in entities]
    assert ids == ["obstacles[0]", "obstacles[1]", "obstacles[2]", "obstacles[3]", "robot"]
    wall, box, cylinder, model, robot = entities
    assert {text(e, 2) for e in (wall, box, cylinder, model)} == {"odom"}
    cube = fields(wall[8][0])
    assert vector(cube[2][0]) == pytest.approx((4.0, 0.1, 0.5))  # length, thickness, height
    assert vector(fields(cube[1][0])[1][0]) == pytest.approx((2.0, 0.0, 0.25))
    assert vector(fields(box[8][0])[2][0]) == pytest.approx((0.2, 0.3, 0.4))
    shape = fields(cylinder[10][0])
    assert vector(shape[2][0]) == pytest.approx((0.4, 0.4, 0.5))
    assert (shape[3], shape[4]) == ([1.0], [1.0])  # bottom and top scale: a cylinder, not a cone
    assert text(fields(model[13][0]), 6) == "table.urdf"
    assert (text(robot, 2), robot[5]) == ("base_footprint", [1])  # follows the robot


def _check_transforms(message: dict[int, list[Any]], t: float) -> None:
    robot, mount = (fields(m) for m in message[1])
    assert (text(robot, 2), text(robot, 3)) == ("odom", "base_footprint")
    assert vector(robot[4][0]) == pytest.approx((1.0, 2.0, 0.0))
    half = math.sqrt(0.5)
    assert vector(robot[5][0], 4) == pytest.approx((0.0, 0.0, half, half))
    stamp = fields(robot[1][0])
    assert stamp.get(1, [0])[0] * 10**9 + stamp.get(2, [0])[0] == _ns(t)
    assert (text(mount, 2), text(mount, 3)) == ("base_footprint", "lidar_scan_frame")
    assert vector(mount[4][0]) == pytest.approx(MOUNT)


def _check_scan(message: dict[int, list[Any]], scan: Scan, t: float) -> None:
    assert text(message, 2) == "lidar_scan_frame"
    assert message[4] == [pytest.approx(scan.angle_min)]
    assert message[5] == [pytest.approx(scan.angle_min + 359 * scan.angle_increment)]
    ranges = np.frombuffer(message[6][0], dtype="<f8")
    np.testing.assert_array_equal(ranges, scan.ranges.astype(np.float64))  # inf included
    stamp = fields(message[1][0])
    assert stamp.get(1, [0])[0] * 10**9 + stamp.get(2, [0])[0] == _ns(t)


def test_a_client_that_comes_later_still_gets_the_world(view: FoxgloveView) -> None:
    async def run() -> Received:
        first = await connect(view.port, {"/world"})
        await first.subscribe(["/world"])
        await first.until({"/world"})
        view.publish_pose(0.5, 0.0, 0.0, 0.0)
        later = await connect(view.port, {"/world"})
        await later.subscribe(["/world"])
        got = await later.until({"/world"})
        await first.ws.close()
        await later.ws.close()
        return got["/world"]

    world = asyncio.run(run())
    assert len(fields(world.payload)[2]) == 5


def test_the_view_knows_who_watches(view: FoxgloveView) -> None:
    assert view.watched() == set()

    async def run() -> None:
        client = await connect(view.port, {"/scan"})
        await client.subscribe(["/scan"])
        await subscribed(view, {"/scan"})
        await client.ws.send(json.dumps({"op": "unsubscribe", "subscriptionIds": [1]}))
        deadline = time.monotonic() + WAIT_S
        while "/scan" in view.watched() and time.monotonic() < deadline:
            await asyncio.sleep(0.005)  # the SDK calls on_unsubscribe; nothing to await
        assert "/scan" not in view.watched()
        view.publish_scan(0.1, a_scan(0.1))  # no watcher: nothing encoded, nothing sent
        await client.ws.close()

    asyncio.run(run())


# -- the port, the end, the extra ------------------------------------------------------


def test_an_occupied_port_is_refused_in_one_line() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ConfigError) as caught:
            FoxgloveView(scenario(), port=port)
    message = str(caught.value)
    assert f"127.0.0.1:{port}" in message and "in use" in message and "\n" not in message


@pytest.mark.parametrize("port", [-1, 65536, True, 8765.0])
def test_a_port_that_is_no_port_is_refused(port: Any) -> None:
    with pytest.raises(ConfigError, match="port"):
        FoxgloveView(scenario(), port=port)


def test_close_is_idempotent_and_frees_the_port() -> None:
    view = FoxgloveView(scenario(), port=0)
    port = view.port

    async def run() -> None:
        client = await connect(port, {"/world", "/scan"})
        await client.subscribe(["/world", "/scan"])
        await subscribed(view, {"/world", "/scan"})  # closing calls back on_unsubscribe
        view.close()
        view.close()
        with pytest.raises(websockets.ConnectionClosed):
            while True:
                await asyncio.wait_for(client.ws.recv(), WAIT_S)

    asyncio.run(run())
    assert view.closed and view.watched() == set()
    view.publish_pose(1.0, 0.0, 0.0, 0.0)  # after close: nothing, no error
    view.publish_scan(1.0, a_scan(1.0))
    view.publish_answer(1.0, "late", False)
    with FoxgloveView(scenario(), port=port) as again:
        assert again.port == port


def test_without_foxglove_sdk_the_view_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "foxglove", None)  # import foxglove raises ImportError
    foxglove_messages.foxglove_sdk.cache_clear()
    try:
        with pytest.raises(ConfigError) as caught:
            FoxgloveView(scenario(), port=0)
    finally:
        monkeypatch.undo()
        foxglove_messages.foxglove_sdk.cache_clear()
    assert str(caught.value) == INSTALL_HINT


# -- the robot's geometry ----------------------------------------------------------


def test_the_lidar_mount_composes_the_urdf_joints() -> None:
    urdf = ET.fromstring(
        """<robot name="r">
          <link name="base"/><link name="plate"/><link name="lidar"/>
          <joint name="a" type="fixed"><parent link="base"/><child link="plate"/>
            <origin xyz="0.1 0 0.2" rpy="0 0 1.5707963267948966"/></joint>
          <joint name="b" type="fixed"><parent link="plate"/><child link="lidar"/>
            <origin xyz="0.05 0 0.01" rpy="0 0 0"/></joint>
        </robot>"""
    )
    placed = lidar_placement(urdf, "lidar")
    assert placed.xyz == pytest.approx((0.1, 0.05, 0.21))  # the plate turned +x into +y
    assert placed.quaternion == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))
    assert lidar_placement(urdf, "base") == Placement()
    with pytest.raises(ConfigError, match="no link named 'laser'"):
        lidar_placement(urdf, "laser")


def test_an_unreadable_robot_urdf_leaves_the_lidar_at_the_origin_and_says_so() -> None:
    with FoxgloveView(scenario(urdf="nowhere.urdf"), port=0) as view:
        (note,) = view.notes
        assert "cannot load 'nowhere.urdf': no such file" in note and "origin" in note


def test_a_verdict_has_no_nan_for_json() -> None:
    expected = Expectation(False, None, None, None, False)
    ok = Verdict(3, 0.3, True, expected, None, False, (), "")
    message = verdict_message(ok)
    assert message["expected_distance"] is None and message["claimed_distance"] is None
    assert (message["expected_warning"], message["warning"]) == (0, 0)
    json.dumps(message, allow_nan=False)


# -- what a publish costs ------------------------------------------------------------


def test_publishing_a_360_beam_scan_fits_a_10_hz_loop(view: FoxgloveView) -> None:
    """Costs per call, with a client subscribed to everything (printed with -s)."""
    every = set(PROTOBUF) | set(JSON)
    scan, rounds = a_scan(1.0), 300

    def measure() -> dict[str, float]:
        costs = {}
        for name, call in (
            ("publish_scan", lambda: view.publish_scan(1.0, scan)),
            ("publish_pose", lambda: view.publish_pose(1.0, 1.0, 2.0, 0.3)),
            ("publish_answer", lambda: view.publish_answer(1.0, "Obstacle at 0.50 m", True)),
        ):
            start = time.perf_counter()
            for _ in range(rounds):
                call()
            costs[name] = (time.perf_counter() - start) / rounds * 1e6
        return costs

    async def run() -> dict[str, float]:
        client = await connect(view.port, every)
        await client.subscribe(sorted(every))
        await subscribed(view, every)
        seen: set[str] = set()

        async def read() -> None:  # as the app does: it reads while the view publishes
            while True:
                seen.add((await client.data()).topic)

        reader = asyncio.create_task(read())
        costs = await asyncio.to_thread(measure)
        deadline = time.monotonic() + WAIT_S
        while not {"/scan", "/tf", "/lidar_status"} <= seen and time.monotonic() < deadline:
            await asyncio.sleep(0.01)  # the reader is on it; nothing to await but time
        reader.cancel()
        await client.ws.close()
        assert {"/scan", "/tf", "/lidar_status"} <= seen
        return costs

    costs = asyncio.run(run())
    print(
        "\nlive view, microseconds per call: " + ", ".join(f"{k} {v:.0f}" for k, v in costs.items())
    )
    assert costs["publish_scan"] < 5_000  # a 10 Hz loop has 100 000 us per scan
