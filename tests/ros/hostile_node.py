#!/usr/bin/env python3
"""Hostile nodes under test: each misbehaves in one way the harness must survive.

Run as ``python3 hostile_node.py VARIANT [--pids FILE] --ros-args ...``.
Every variant otherwise answers each scan correctly (nearest valid return,
warning below the threshold), so the misbehaviour is the only thing wrong.
With ``--pids FILE`` the node appends ``PID STARTTIME`` for itself and for
every process it starts, so a test can prove that none outlives the run.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, Int32, String

# Mid-run variants misbehave from the scan stamped this (simulated) time on:
# tick 2 at 10 Hz, however often the harness had to resend its warm-up scan.
MISBEHAVE_AT_S = 0.2


def start_time(pid: int) -> str:
    """Start time in clock ticks (/proc/PID/stat field 22): with the pid, unique."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return stat.rsplit(")", 1)[1].split()[19]


def record_pid(pids: Path | None, pid: int) -> None:
    if pids is not None:
        with pids.open("a") as handle:
            handle.write(f"{pid} {start_time(pid)}\n")


class Answering(Node):
    """A correct Lab 07 node; `on_scan` hooks let each variant break one thing."""

    def __init__(
        self,
        status_type: type = String,
        warning_type: type = Bool,
        status_topic: str | None = None,
        *,
        subscribe: bool = True,
        answer_qos: QoSProfile | int = 10,
    ) -> None:
        """`subscribe` false: no scan subscription yet (a variant makes it later).

        A variant gets its own topics and QoS here, never by destroying an endpoint and
        making another: one made and destroyed again can stay matched in the harness's
        view for seconds (a /scan reader so made counted as the node reading the scans)."""
        super().__init__("fossbot_lidar_node")
        self.declare_parameter("lidar_topic", "/scan")
        self.declare_parameter("lidar_status_topic", "/lidar_status")
        self.declare_parameter("warning_topic", "/obstacle_warning")
        self.declare_parameter("threshold", 0.5)
        self.threshold = self.get_parameter("threshold").value
        self.before_answer: Callable[[float], None] = lambda stamp: None
        self.status_topic = status_topic or self.get_parameter("lidar_status_topic").value
        self.status_pub = self.create_publisher(status_type, self.status_topic, answer_qos)
        self.warning_pub = self.create_publisher(
            warning_type, self.get_parameter("warning_topic").value, answer_qos
        )
        self.sub = (
            self.create_subscription(
                LaserScan, self.get_parameter("lidar_topic").value, self.on_scan, 10
            )
            if subscribe
            else None
        )

    def on_scan(self, msg: LaserScan) -> None:
        self.before_answer(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9)
        best, index = math.inf, None
        for i, r in enumerate(msg.ranges):
            if math.isfinite(r) and msg.range_min <= r <= msg.range_max and r < best:
                best, index = r, i
        if index is None:
            self.answer("No obstacle", False)
        else:
            angle = msg.angle_min + index * msg.angle_increment
            self.answer(f"Obstacle at {best:.3f} m, {angle:.3f} rad", best < self.threshold)

    def answer(self, text: str, warning: bool) -> None:
        self.status_pub.publish(String(data=text))
        self.warning_pub.publish(Bool(data=warning))


# -- variants: each builds its node (or never gets that far) ------------------


def crash_at_start(pids: Path | None) -> Node:
    raise RuntimeError("hostile: crash before the node exists")


def crash_mid_run(pids: Path | None) -> Node:
    node = Answering()

    def crash(stamp: float) -> None:
        if stamp >= MISBEHAVE_AT_S - 1e-6:
            raise RuntimeError(f"hostile: crash in the callback of the scan stamped {stamp:.1f} s")

    node.before_answer = crash
    return node


def crash_on_first_scan(pids: Path | None) -> Node:
    """Ready, then raises in the callback of the very first scan (tick 0's)."""
    node = Answering()

    def crash(stamp: float) -> None:
        raise RuntimeError("hostile: crash in the callback of the first scan")

    node.before_answer = crash
    return node


def hang(pids: Path | None) -> Node:
    """Blocks forever inside the scan callback."""
    node = Answering()
    stuck = threading.Event()

    def block(stamp: float) -> None:
        if stamp >= MISBEHAVE_AT_S - 1e-6:
            stuck.wait()

    node.before_answer = block
    return node


def exits_early(pids: Path | None) -> Node:
    """'Finishes' with exit code 0 after a few scans."""
    node = Answering()

    def finish(stamp: float) -> None:
        if stamp >= MISBEHAVE_AT_S - 1e-6:
            os._exit(0)

    node.before_answer = finish
    return node


def _flood(body: Callable[[], None]) -> None:
    threading.Thread(target=lambda: [body() for _ in iter(int, 1)], daemon=True).start()


def flood_status(pids: Path | None) -> Node:
    """Publishes status Strings as fast as it can, besides its answers."""
    node = Answering()
    flood = String(data="flood")
    _flood(lambda: node.status_pub.publish(flood))
    return node


def flood_warning(pids: Path | None) -> Node:
    """Publishes warning Bools as fast as it can, besides its answers."""
    node = Answering()
    flood = Bool(data=False)
    _flood(lambda: node.warning_pub.publish(flood))
    return node


def flood_output(pids: Path | None) -> Node:
    """Writes to stdout and stderr as fast as it can (a print in a hot loop, gone wrong)."""
    line = "x" * 200 + "\n"
    _flood(lambda: (sys.stdout.write(line), sys.stderr.write(line)))
    return Answering()


def bool_held_up(pids: Path | None) -> Node:
    """String first, then the Bool; every fifth scan the Bool comes 50 ms after the String
    (a busy thread in the node), by which time the harness has sent the next scan."""
    node = Answering()
    count = 0

    def answer(text: str, warning: bool) -> None:
        nonlocal count
        count += 1
        node.status_pub.publish(String(data=text))
        if count % 5 == 0:
            time.sleep(0.05)
        node.warning_pub.publish(Bool(data=warning))

    node.answer = answer
    return node


def status_as_bool(pids: Path | None) -> Node:
    """Publishes a Bool on the status topic (and no String anywhere)."""
    node = Answering(status_type=Bool)
    node.answer = lambda text, warning: node.status_pub.publish(Bool(data=warning))
    return node


def warning_as_int32(pids: Path | None) -> Node:
    """A String status, but the warning as std_msgs/Int32."""
    node = Answering(warning_type=Int32)

    def answer(text: str, warning: bool) -> None:
        node.status_pub.publish(String(data=text))
        node.warning_pub.publish(Int32(data=int(warning)))

    node.answer = answer
    return node


def best_effort(pids: Path | None) -> Node:
    """Publishes status and warning best-effort (sensor-data QoS copied from the scan)."""
    return Answering(answer_qos=qos_profile_sensor_data)


def status_topic_wrong(pids: Path | None) -> Node:
    """Publishes its status on /lidar_status_wrong, whatever the parameter says."""
    return Answering(status_topic="/lidar_status_wrong")


def status_parameter_ignored(pids: Path | None) -> Node:
    """Publishes on /lidar_status, ignoring the lidar_status_topic parameter.

    The parameter's topic is never offered, not even for a moment: a
    publisher made and destroyed again stays in other participants' view of
    the graph for a while, and the harness would rightly count it as ready.
    """
    return Answering(status_topic="/lidar_status")


def waits_for_clock(pids: Path | None) -> Node:
    """Publishes its status and warning at once, but subscribes to the scans only once a
    /clock message came (a node that needs sim time before it starts its work).

    Its scan subscription is never made before that, not even for a moment: one made and
    destroyed again was seen matched by the harness's /scan writer seconds later (a reader
    whose removal discovery had not yet told), and the node counted as ready with no clock.
    """
    from rosgraph_msgs.msg import Clock

    node = Answering(subscribe=False)
    topic = node.get_parameter("lidar_topic").value

    def on_clock(msg: Clock) -> None:
        if node.sub is None:
            node.get_logger().info(f"first /clock: {msg.clock.sec}.{msg.clock.nanosec:09d}")
            node.sub = node.create_subscription(LaserScan, topic, node.on_scan, 10)

    node.clock_sub = node.create_subscription(Clock, "/clock", on_clock, 10)
    return node


def ignores_signals(pids: Path | None) -> Node:
    """Ignores SIGINT and SIGTERM: only SIGKILL ends it."""
    node = Answering()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return node


# Terminal and XML poison: erase, reset, bell, carriage return, a bidi
# override, a C1 control, rich markup, then NUL (a ROS String ends there);
# on stderr also invalid UTF-8 (a lone surrogate's bytes). No digits in the
# status: it must read as claiming nothing.
POISON = "\x1b[J\x1bc\x07\r\u202e\x9b\x0b\x0c[bold]x[/] \x00"
POISON_BYTES = POISON.encode() + b" \xff\xfe \xed\xa0\x80 \x1b]0;title\x07\r\n"


def control_characters(pids: Path | None) -> Node:
    """Writes escape sequences, NUL, CR, bidi overrides and invalid UTF-8 to stderr on every
    scan, answers with a status full of them (and wrong: it claims nothing), then exits
    with code 1 at tick 2, so they reach the error text (its last stderr) too."""
    node = Answering()

    def poison(stamp: float) -> None:
        os.write(2, b"hostile " + POISON_BYTES)
        if stamp >= MISBEHAVE_AT_S - 1e-6:
            os._exit(1)

    node.before_answer = poison
    node.answer = lambda text, warning: node.status_pub.publish(String(data=f"none {POISON}"))
    return node


DAEMON = """
import os, sys, time
if os.fork():
    os._exit(0)
os.setsid()
if os.fork():
    os._exit(0)
stat = open(f"/proc/{os.getpid()}/stat").read().rsplit(")", 1)[1].split()
with open(sys.argv[1], "a") as handle:
    handle.write(f"{os.getpid()} {stat[19]}\\n")
while True:
    time.sleep(60)
"""


def leaves_children(pids: Path | None) -> Node:
    """Starts a child in its own process group and a daemon in a new session; neither stops.

    The child ignores SIGINT and SIGTERM; the daemon double-forks away from the node.
    """
    assert pids is not None, "leaves_children needs --pids FILE"
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import signal, time\n"
            "signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
            "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
            "while True: time.sleep(60)",
        ],
        start_new_session=True,
    )
    record_pid(pids, child.pid)
    subprocess.run([sys.executable, "-c", DAEMON, str(pids)], check=True, timeout=10)
    deadline = time.monotonic() + 10
    while len(pids.read_text().splitlines()) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)  # bounded poll: the daemon has written its pid
    return Answering()


VARIANTS: dict[str, Callable[[Path | None], Node]] = {
    f.__name__: f
    for f in (
        crash_at_start,
        crash_mid_run,
        crash_on_first_scan,
        hang,
        exits_early,
        flood_status,
        flood_warning,
        flood_output,
        status_as_bool,
        warning_as_int32,
        bool_held_up,
        best_effort,
        status_topic_wrong,
        status_parameter_ignored,
        waits_for_clock,
        ignores_signals,
        leaves_children,
        control_characters,
    )
}


def main() -> None:
    args = sys.argv[1:]
    if not args or args[0] not in VARIANTS:
        sys.exit(f"usage: hostile_node.py {{{','.join(VARIANTS)}}} [--pids FILE] --ros-args ...")
    pids = Path(args[args.index("--pids") + 1]) if "--pids" in args else None
    record_pid(pids, os.getpid())
    rclpy.init(args=sys.argv)
    node = VARIANTS[args[0]](pids)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
