"""Read LaserScans back from a recording: ours, or a robot's rosbag2.

Accepts a bare MCAP file, a rosbag2 directory (MCAP or SQLite storage) or
a ``.db3`` file. Every problem with the file is a ConfigError naming it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from harness.errors import ConfigError
from harness.lidar.scan import Scan, scan_from_message
from harness.option_names import named
from harness.record import messages as msg
from harness.record.writer import METADATA_NAME, RecordTopics


@dataclass(frozen=True)
class RecordedScans:
    """The scans of one topic, in recorded order, with what else the file knows."""

    source: str
    topic: str
    scans: list[Scan]
    times: list[float]  # seconds since the first scan, from the log times
    poses: list[tuple[float, float, float]] | None = None  # x, y, yaw per scan, when recorded
    run: dict[str, str] = field(default_factory=dict)  # our run metadata, when ours


def _run_metadata(path: Path) -> dict[str, str]:
    if path.suffix != ".mcap":
        return {}
    from mcap.reader import make_reader

    try:
        with path.open("rb") as stream:
            for record in make_reader(stream).iter_metadata():
                if record.name == METADATA_NAME:
                    return dict(record.metadata)
    except Exception:  # noqa: BLE001 - a foreign or damaged file simply has none
        return {}
    return {}


def _choose_topic(path: Path, scan_topics: list[str], topic: str | None) -> str:
    if topic is not None:
        if topic not in scan_topics:
            known = ", ".join(scan_topics) or "none"
            raise ConfigError(f"{path}: no LaserScan topic {topic!r} (LaserScan topics: {known})")
        return topic
    if not scan_topics:
        raise ConfigError(f"{path}: no sensor_msgs/msg/LaserScan topic in this recording")
    if RecordTopics.scan in scan_topics:
        return RecordTopics.scan
    if len(scan_topics) > 1:
        raise ConfigError(
            f"{path}: several LaserScan topics ({', '.join(scan_topics)}); "
            f"choose one with {named('topic')}"
        )
    return scan_topics[0]


def read_scans(path: str | Path, topic: str | None = None) -> RecordedScans:
    """The LaserScans on `topic` (default ``/scan``, or the only LaserScan topic)."""
    from rosbags.highlevel import AnyReader

    source = Path(path)
    if not source.exists():
        raise ConfigError(f"{source}: no such file or directory")
    try:
        with AnyReader([source], default_typestore=msg.typestore()) as reader:
            scan_topics = sorted(
                {c.topic for c in reader.connections if c.msgtype == msg.LASER_SCAN}
            )
            chosen = _choose_topic(source, scan_topics, topic)
            wanted = [c for c in reader.connections if c.topic in (chosen, RecordTopics.pose)]
            scans: list[Scan] = []
            times: list[int] = []
            poses: list[tuple[float, float, float]] = []
            for connection, when, raw in reader.messages(connections=wanted):
                message = reader.deserialize(raw, connection.msgtype)
                if connection.topic == chosen:
                    scans.append(scan_from_message(message))
                    times.append(when)
                elif connection.msgtype == msg.POSE:
                    poses.append(msg.planar_pose(message))
    except ConfigError:
        raise
    except Exception as err:  # noqa: BLE001 - rosbags raises many kinds; all mean "unreadable"
        reason = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ConfigError(f"{source}: not a readable recording ({reason})") from None
    if not scans:
        raise ConfigError(f"{source}: topic {chosen!r} holds no messages")
    seconds = [(t - times[0]) * 1e-9 for t in times]
    matched = poses if len(poses) == len(scans) else None  # one pose per scan, or none
    return RecordedScans(str(source), chosen, scans, seconds, matched, _run_metadata(source))
