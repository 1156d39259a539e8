"""`fossbot-hil sim` for real: its own process, driven over /cmd_vel from this one, over DDS.

The robot must move as the physics says: forward while commanded (the
nearest return falls as it nears the wall), stopped half a second after
the commands stop, and stopped by the wall however long it is pushed.
The live judge passes the reference node and catches a node that reports
its angle in degrees.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from command_line import COMMAND, fossbot_hil

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(120)]

WALL_FACE_X = 1.95  # single_wall: the wall's centre line is x = 2.0, 0.1 m thick
SIM_SECONDS = 40.0  # long enough for every step below; the test ends it with Ctrl-C


@dataclass
class Seen:
    """What the test process heard from the simulator."""

    odom: list[tuple[float, float, float]] = field(default_factory=list)  # (when, x, speed)
    nearest: list[float] = field(default_factory=list)  # each scan's nearest finite return


@contextlib.contextmanager
def own_domain() -> Iterator[list[str]]:
    """A ROS domain of the test's own, as the sim's options: sims never meet (a sim's
    default is the shell's domain, 0, which parallel tests would share)."""
    from harness.ros.domain import reserve_domain

    with reserve_domain() as domain:
        yield ["--domain-id", str(domain.domain_id)]


def _nearest(ranges: list[float]) -> float:
    return min((r for r in ranges if math.isfinite(r)), default=math.inf)


@pytest.fixture
def driver() -> Iterator[tuple[subprocess.Popen[str], Callable[..., None], Seen]]:
    """A running `fossbot-hil sim single_wall` and a way to drive it and hear it."""
    import rclpy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import LaserScan

    from harness.ros.domain import discovery_environment, reserve_domain

    with reserve_domain() as domain:
        sim = subprocess.Popen(
            [*COMMAND, "sim", "single_wall", "--duration", str(SIM_SECONDS)]
            + ["--foxglove-port", "off", "--domain-id", str(domain.domain_id)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env={**os.environ, **discovery_environment(network=False)},
        )
        context = Context()
        rclpy.init(context=context, domain_id=domain.domain_id)
        node = rclpy.create_node("test_driver", context=context)
        seen = Seen()
        node.create_subscription(
            Odometry,
            "/odom",
            lambda m: seen.odom.append(
                (time.monotonic(), m.pose.pose.position.x, m.twist.twist.linear.x)
            ),
            50,
        )
        node.create_subscription(
            LaserScan,
            "/scan",
            lambda m: seen.nearest.append(
                min((r for r in m.ranges if math.isfinite(r)), default=math.inf)
            ),
            50,
        )
        cmd = node.create_publisher(Twist, "/cmd_vel", 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)

        def drive(
            linear: float, seconds: float, *, until: Callable[[], bool] | None = None
        ) -> None:
            """Publish `linear` at 20 Hz (none when None) for `seconds`, hearing all the while."""
            end = time.monotonic() + seconds
            due = 0.0
            while time.monotonic() < end and not (until and until()):
                assert sim.poll() is None, sim.stdout.read() if sim.stdout else ""
                if linear is not None and time.monotonic() >= due:
                    twist = Twist()
                    twist.linear.x = linear
                    cmd.publish(twist)
                    due = time.monotonic() + 0.05
                executor.spin_once(timeout_sec=0.01)

        try:
            # Up, and hearing us: commands sent before discovery matched would be lost.
            def up() -> bool:
                heard = len(seen.odom) > 5 and bool(seen.nearest)
                return heard and cmd.get_subscription_count() > 0

            drive(None, 20.0, until=up)
            assert up(), (
                f"the simulator never came up: {len(seen.odom)} odometry messages, "
                f"{len(seen.nearest)} scans, {cmd.get_subscription_count()} /cmd_vel subscribers"
            )
            yield sim, drive, seen
        finally:
            if sim.poll() is None:
                sim.send_signal(signal.SIGINT)
            try:
                sim.wait(timeout=20)
            finally:
                if sim.poll() is None:
                    sim.kill()
            executor.shutdown()
            node.destroy_node()
            rclpy.shutdown(context=context)


def test_cmd_vel_drives_the_robot_and_the_wall_stops_it(driver) -> None:
    sim, drive, seen = driver
    x0, near0 = seen.odom[-1][1], seen.nearest[-1]

    drive(0.3, 2.0)
    x1 = seen.odom[-1][1]
    assert x1 - x0 > 0.3, f"0.3 m/s for 2 s moved the robot {x1 - x0:.3f} m"
    assert seen.nearest[-1] < near0 - 0.3, (near0, seen.nearest[-1])

    drive(None, 1.0)  # no commands: stopped after about half a second
    resting = [x for when, x, _ in seen.odom if when > time.monotonic() - 0.3]
    assert resting and max(resting) - min(resting) < 0.005, resting
    assert abs(seen.odom[-1][2]) < 0.01

    drive(1.0, 10.0)  # flat out at the wall, for longer than it takes to reach it
    x_end = max(x for _, x, _ in seen.odom)
    assert x_end < WALL_FACE_X, f"the robot went through the wall: x = {x_end:.3f}"
    assert seen.nearest[-1] < 0.25, "the robot stopped short of the wall"
    assert min(seen.nearest) > 0.0

    sim.send_signal(signal.SIGINT)  # Ctrl-C is the normal end
    out, _ = sim.communicate(timeout=20)
    assert sim.returncode == 0, out
    assert "ended by SIGINT" in out and "/cmd_vel commands" in out


@pytest.mark.parametrize(
    "node, code, says",
    [
        (f"{sys.executable} -m harness.reference.lidar_node", 0, "PASS"),
        (f"{sys.executable} tests/ros/student_node.py angle_in_degrees", 1, "looks like degrees"),
    ],
    ids=["reference", "degrees"],
)
def test_the_live_judge_passes_a_right_node_and_explains_a_wrong_one(
    node: str, code: int, says: str, tmp_path: Path
) -> None:
    evidence = ["--record", str(tmp_path / "records"), "--animation", str(tmp_path / "s.gif")]
    with own_domain() as domain:
        done = fossbot_hil(
            "sim", "obstacle_at_side", "--duration", "2", "--foxglove-port", "off", "--node", node,
            *evidence, *domain, timeout=120,
        )  # fmt: skip
    assert done.returncode == code, done.stdout + done.stderr
    assert says in done.stdout
    assert "live" in done.stdout  # the table's link column
    assert (tmp_path / "records" / "obstacle_at_side.mcap").stat().st_size > 0
    assert (tmp_path / "s.gif").read_bytes().startswith(b"GIF8")


@pytest.mark.parametrize(
    "args, message",
    [
        (["--rate", "0"], "--rate"),
        (["--foxglove-port", "70000"], "1-65535"),
        (["no_such_world"], "unknown world 'no_such_world'"),
        (["--realtime"], "--realtime"),
        (["--record", "/proc/version/x"], "--record /proc/version/x: cannot make this folder"),
        (["--faults", "drop(rate=0.1)"], "link faults apply to `run`"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args: list[str], message: str) -> None:
    with own_domain() as domain:
        done = fossbot_hil(
            "sim", "--duration", "1", "--foxglove-port", "off", *domain, *args, timeout=60
        )
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], done.stderr


def test_teleop_drives_from_the_terminal_with_the_labs_keys() -> None:
    """`--teleop` on a real pty: `i` drives forward (over /cmd_vel), to the wall."""
    import os
    import pty
    import select

    from harness.ros.domain import reserve_domain

    master, slave = pty.openpty()
    with reserve_domain() as domain:
        sim = subprocess.Popen(
            [*COMMAND, "sim", "single_wall", "--teleop", "--duration", "4"]
            + ["--foxglove-port", "off", "--domain-id", str(domain.domain_id)],
            stdin=slave,
            stdout=slave,
            stderr=slave,
            start_new_session=True,
        )
        os.close(slave)
        out, typed = b"", False
        deadline = time.monotonic() + 60
        try:
            while time.monotonic() < deadline:
                readable, _, _ = select.select([master], [], [], 0.1)
                chunk = b""
                if readable:
                    try:
                        chunk = os.read(master, 65536)
                    except OSError:  # the other side closed: the command has ended
                        break
                    out += chunk
                if not typed and b"is live" in out:
                    os.write(master, b"i")
                    typed = True
                if not chunk and sim.poll() is not None:
                    break
            assert sim.wait(timeout=20) == 0, out.decode(errors="replace")
        finally:
            if sim.poll() is None:
                sim.kill()
            os.close(master)
    text = out.decode(errors="replace")
    assert typed, text
    assert "speed" in text  # the keyboard's help and speed line
    ended = text[text.index("the robot ended at x") :].split()
    assert float(ended[5]) > 1.0, text[-500:]  # driven towards the wall at x = 2


def test_sim_serves_the_foxglove_view() -> None:
    """`sim` advertises its world, scan and answers to a real Foxglove client."""
    import asyncio
    import json
    import socket

    import websockets

    with socket.socket() as probe:  # a free port (released just before sim takes it)
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]

    async def advertised(sim: subprocess.Popen[str]) -> set[str]:
        deadline = time.monotonic() + 30
        while True:  # the simulator takes a moment to come up
            try:
                ws = await websockets.connect(
                    f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"]
                )
                break
            except OSError:
                assert time.monotonic() < deadline and sim.poll() is None, "no view"
                await asyncio.sleep(0.2)
        topics: set[str] = set()
        async with ws:
            while "/world" not in topics or "/scan" not in topics:
                message = await asyncio.wait_for(ws.recv(), 10)
                if isinstance(message, str) and json.loads(message).get("op") == "advertise":
                    topics |= {c["topic"] for c in json.loads(message)["channels"]}
        return topics

    with own_domain() as domain:
        sim = subprocess.Popen(
            [*COMMAND, "sim", "single_wall", "--duration", "30", "--foxglove-port", str(port)]
            + domain,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        try:
            topics = asyncio.run(advertised(sim))
        finally:
            sim.send_signal(signal.SIGINT)
            out, _ = sim.communicate(timeout=20)
    assert {"/scan", "/world", "/tf", "/lidar_status", "/obstacle_warning"} <= topics
    assert f"ws://127.0.0.1:{port}" in out and sim.returncode == 0, out
