"""Recordings read back by independent readers match the run's trace."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.record import read_scans, write_recording
from harness.runner.scenario_run import run
from harness.scenario.files import resolve_scenario

STUDENTS = Path(__file__).parents[1] / "student_functions.py"
PROCESSOR = f"{STUDENTS}:min_over_raw_ranges"
SCENARIO = "drive_past_10m"


@pytest.fixture(scope="module")
def failing_run() -> RunResult:
    """A run with passing and failing ticks: min() over raw ranges, past 10 m."""
    options = LinkOptions(processor=PROCESSOR)
    result = run(resolve_scenario(SCENARIO), "inprocess", options)
    assert result.failed_ticks and len(result.failed_ticks) < len(result.records)
    return result


@dataclass(frozen=True)
class Decoded:
    log_time_ns: int
    ros_msg: Any


def _by_topic(path: Path) -> dict[str, list[Decoded]]:
    """Every message, decoded by mcap-ros2-support's own CDR reader, per topic."""
    topics: dict[str, list[Decoded]] = {}
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            topics.setdefault(channel.topic, []).append(Decoded(message.log_time, decoded))
    return topics


def test_mcap_ros2_reader_sees_every_stream_of_the_trace(
    failing_run: RunResult, tmp_path: Path
) -> None:
    """mcap-ros2-support (its own CDR decoder) reads what the trace holds, tick by tick."""
    path = write_recording(tmp_path / "run.mcap", failing_run)
    topics = _by_topic(path)
    records = failing_run.records
    expected_topics = {"/scan", "/clock", "/lidar_status", "/obstacle_warning"}
    expected_topics |= {"/fossbot_hil/pose", "/fossbot_hil/verdict"}
    assert set(topics) == expected_topics
    assert all(len(topics[t]) == len(records) for t in topics)

    for record, item in zip(records, topics["/scan"], strict=True):
        msg = item.ros_msg
        assert item.log_time_ns == round(record.t * 1e9)
        assert msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9 == pytest.approx(record.t)
        assert msg.angle_min == np.float32(record.scan.angle_min)
        np.testing.assert_array_equal(np.asarray(msg.ranges, np.float32), record.scan.ranges)

    statuses = [m.ros_msg.data for m in topics["/lidar_status"]]
    assert statuses == [r.answers.statuses[0].value for r in records]
    warnings = [m.ros_msg.data for m in topics["/obstacle_warning"]]
    assert warnings == [r.answers.warnings[0].value for r in records]

    verdicts = [m.ros_msg for m in topics["/fossbot_hil/verdict"]]
    assert [(v.tick, v.ok, v.explanation) for v in verdicts] == [
        (r.tick, r.verdict.ok, r.verdict.explanation) for r in records
    ]
    failed = next(v for v in verdicts if not v.ok)
    assert "expected no obstacle" in failed.explanation

    for record, item in zip(records, topics["/fossbot_hil/pose"], strict=True):
        pose = item.ros_msg.pose
        assert (pose.position.x, pose.position.y) == pytest.approx((record.x, record.y))
        yaw = 2 * math.atan2(pose.orientation.z, pose.orientation.w)
        assert yaw == pytest.approx(record.yaw)


def test_recording_names_the_run_in_its_metadata(failing_run: RunResult, tmp_path: Path) -> None:
    """Replay finds threshold and noise here; readers see scenario, link and verdict."""
    path = write_recording(tmp_path / "run.mcap", failing_run)
    with path.open("rb") as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == "ros2"
        meta = {m.name: m.metadata for m in reader.iter_metadata()}["fossbot_hil_run"]
    assert meta["scenario"] == SCENARIO and meta["link"] == "inprocess"
    assert float(meta["threshold"]) == failing_run.threshold
    assert meta["ok"] == "false"
    assert int(meta["failed_ticks"]) == len(failing_run.failed_ticks)


def test_rosbags_reads_the_scans_back_exactly(failing_run: RunResult, tmp_path: Path) -> None:
    """The replay reader (rosbags) gets the float32 scans, times and poses of the run."""
    recording = read_scans(write_recording(tmp_path / "run.mcap", failing_run))
    assert recording.topic == "/scan"
    assert len(recording.scans) == len(failing_run.records)
    for record, scan, t in zip(failing_run.records, recording.scans, recording.times, strict=True):
        np.testing.assert_array_equal(scan.ranges, record.scan.ranges)
        assert scan.angle_increment == np.float32(record.scan.angle_increment)
        assert t == pytest.approx(record.t)
    assert recording.poses is not None
    assert recording.poses[-1] == pytest.approx(
        (failing_run.records[-1].x, failing_run.records[-1].y, failing_run.records[-1].yaw)
    )


def test_a_failed_write_leaves_nothing_under_the_name(
    failing_run: RunResult, tmp_path: Path
) -> None:
    """Atomic: a recording that cannot be completed leaves no file, not even a temporary."""
    target = tmp_path / "run.mcap"
    target.write_bytes(b"the previous recording")
    broken = RunResult(**{**failing_run.__dict__, "records": [*failing_run.records, None]})
    with pytest.raises(AttributeError):
        write_recording(target, broken)
    assert target.read_bytes() == b"the previous recording"
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]


def test_recordings_are_reproducible(failing_run: RunResult, tmp_path: Path) -> None:
    """A recording is a function of the run; a rerun differs only in answer latencies."""
    first = write_recording(tmp_path / "a.mcap", failing_run).read_bytes()
    assert write_recording(tmp_path / "b.mcap", failing_run).read_bytes() == first

    again = run(resolve_scenario(SCENARIO), "inprocess", LinkOptions(processor=PROCESSOR))
    rerun = write_recording(tmp_path / "c.mcap", again)

    def contents(path: Path) -> list[tuple[str, bytes]]:
        with path.open("rb") as stream:
            return sorted((c.topic, m.data) for _, c, m in make_reader(stream).iter_messages())

    assert contents(rerun) == contents(tmp_path / "a.mcap")
