"""Replaying a recording judges the node exactly as the original run did."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from command_line import fossbot_hil

from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.record import read_scans, write_recording
from harness.runner.replay import replay
from harness.runner.scenario_run import run
from harness.scenario.files import resolve_scenario

TESTS = Path(__file__).parents[1]
STUDENTS = TESTS / "student_functions.py"
STUDENT_NODE = TESTS / "ros" / "student_node.py"


def _verdicts(result: RunResult) -> list[tuple[int, bool, str]]:
    return [(r.tick, r.verdict.ok, r.verdict.explanation) for r in result.records]


def test_inprocess_replay_gives_the_original_verdicts(tmp_path: Path) -> None:
    """Same scans, same threshold and band from the recording: the same verdict on every tick."""
    options = LinkOptions(processor=f"{STUDENTS}:min_over_raw_ranges")
    original = run(resolve_scenario("drive_past_10m"), "inprocess", options)
    path = write_recording(tmp_path / "drive_past_10m.mcap", original)
    replayed = replay(read_scans(path), "inprocess", options)
    assert replayed.scenario == "drive_past_10m" and replayed.threshold == original.threshold
    assert _verdicts(replayed) == _verdicts(original)
    assert [r.x for r in replayed.records] == [r.x for r in original.records]


def test_a_noisy_run_replays_with_its_band(tmp_path: Path) -> None:
    """The fault profile's noise widens the threshold band; the recording carries it."""
    scenario = resolve_scenario("noisy_approach")
    original = run(scenario, "inprocess", LinkOptions())
    assert original.noise_sigma > 0
    replayed = replay(
        read_scans(write_recording(tmp_path / "n.mcap", original)), "inprocess", LinkOptions()
    )
    assert replayed.noise_sigma == original.noise_sigma
    assert _verdicts(replayed) == _verdicts(original)
    # The node receives float32 angles; the recording holds what it received.
    for again, first in zip(replayed.records, original.records, strict=True):
        assert again.verdict.expected.warning == first.verdict.expected.warning
        assert again.verdict.expected.angle == pytest.approx(first.verdict.expected.angle)


@pytest.mark.ros
@pytest.mark.timeout(180)
def test_ros2_replay_of_a_buggy_node_gives_the_same_verdicts(tmp_path: Path) -> None:
    """Over real DDS, a student node recorded failing some ticks fails the same ticks on replay,
    through the `fossbot-hil replay` command."""
    node = f"{sys.executable} {STUDENT_NODE} angle_without_angle_min"
    original = run(resolve_scenario("drive_past_10m"), "ros2", LinkOptions(node=node))
    assert original.error is None and 0 < len(original.failed_ticks) < len(original.records)
    path = write_recording(tmp_path / "original.mcap", original)

    again = tmp_path / "replayed.mcap"
    done = fossbot_hil("replay", str(path), "--node", node, "--record", str(again), timeout=120)
    assert done.returncode == 1, done.stdout + done.stderr
    assert original.first_failure is not None and original.first_failure in done.stdout
    replayed = read_scans(again)
    assert replayed.run["failed_ticks"] == str(len(original.failed_ticks))
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with again.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        verdicts = [
            (m.tick, m.ok, m.explanation)
            for _, channel, _, m in reader.iter_decoded_messages(log_time_order=True)
            if channel.topic == "/fossbot_hil/verdict"
        ]
    # A verdict is logged at its tick's time plus how long its answers took: a slow
    # first answer (the node's first callback) is logged after the next tick's verdict.
    assert sorted(verdicts) == _verdicts(original)


def _robot_bag(path: Path, storage: str, *, extra_scan_topic: bool = False) -> Path:
    """A bag as `ros2 bag record /scan` leaves it: rclpy's own CDR bytes, epoch stamps,
    an rplidar_ros-style scan (inf for no return) at the lab robot's drifting ~6.7 Hz."""
    from rclpy.serialization import serialize_message
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore
    from sensor_msgs.msg import LaserScan

    store = get_typestore(Stores.ROS2_JAZZY)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    rng = np.random.default_rng(7)
    start_ns = 1_763_800_000_000_000_000
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        topics = ["/front/scan", "/rear/scan"] if extra_scan_topic else ["/scan"]
        connections = [
            writer.add_connection(t, "sensor_msgs/msg/LaserScan", typestore=store) for t in topics
        ]
        odom = writer.add_connection("/cmd_vel", "geometry_msgs/msg/Twist", typestore=store)
        when = start_ns
        for k in range(40):
            message = LaserScan()
            message.header.stamp.sec, message.header.stamp.nanosec = divmod(when, 1_000_000_000)
            message.header.frame_id = "laser"
            message.angle_min, message.angle_max = -math.pi, math.pi
            message.angle_increment = 2 * math.pi / 360
            message.scan_time, message.range_min, message.range_max = 0.15, 0.15, 12.0
            ranges = np.full(360, np.inf, np.float32)
            ranges[170:190] = 2.0 - 0.045 * k  # a wall ahead, coming closer
            message.ranges = ranges.tolist()
            for connection in connections:
                writer.write(connection, when, serialize_message(message))
            writer.write(
                odom,
                when,
                bytes(
                    store.serialize_cdr(
                        store.types["geometry_msgs/msg/Twist"](
                            linear=store.types["geometry_msgs/msg/Vector3"](x=0.3, y=0.0, z=0.0),
                            angular=store.types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                        ),
                        "geometry_msgs/msg/Twist",
                    )
                ),
            )
            when += int((0.15 + rng.uniform(-0.03, 0.03)) * 1e9)
    return path


@pytest.mark.ros  # the bag's bytes come from rclpy's serializer
@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_robot_rosbag2_replays_with_a_given_threshold(tmp_path: Path, storage: str) -> None:
    """A robot's rosbag2 folder (Humble's SQLite or Jazzy's MCAP storage) is judged too."""
    bag = _robot_bag(tmp_path / "robot_bag", storage)
    recording = read_scans(bag)
    assert recording.topic == "/scan" and len(recording.scans) == 40 and recording.poses is None
    assert 0.12 < recording.times[1] < 0.18

    done = fossbot_hil("replay", str(bag), "--link", "inprocess", "--threshold", "0.5")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "40" in done.stdout

    done = fossbot_hil(
        "replay",
        str(bag),
        "--link",
        "inprocess",
        "--threshold",
        "0.5",
        "--processor",
        f"{STUDENTS}:angle_in_degrees",
    )
    assert done.returncode == 1 and "looks like degrees" in done.stdout


@pytest.mark.ros
def test_replay_input_errors_are_one_line(tmp_path: Path) -> None:
    """Each problem with the recording exits 2 with one line naming the file."""
    bag = _robot_bag(tmp_path / "two_scans", "mcap", extra_scan_topic=True)
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"not an mcap file at all")
    cases = [
        ([str(tmp_path / "missing.mcap")], "no such file or directory"),
        ([str(garbage)], "not a readable recording"),
        ([str(bag), "--threshold", "0.5"], "several LaserScan topics (/front/scan, /rear/scan)"),
        ([str(bag), "--threshold", "0.5", "--topic", "/nope"], "no LaserScan topic '/nope'"),
        ([str(bag), "--topic", "/rear/scan"], "does not say its threshold; give --threshold M"),
        ([str(bag), "--topic", "/cmd_vel", "--threshold", "1"], "no LaserScan topic '/cmd_vel'"),
    ]
    for args, needle in cases:
        done = fossbot_hil("replay", *args, "--link", "inprocess")
        assert done.returncode == 2, (args, done.stdout, done.stderr)
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and needle in lines[0], (args, done.stderr)
