"""Write a run as an MCAP file (ROS 2 profile, CDR messages), atomically.

Log times are simulated time, an answer at its scan's plus the latency it
came with, so lockstep runs read like real-time ones. Where a board's driver
republished the scan, the scan the node really saw is kept too.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType, Writer

from harness import __version__
from harness.atomic_write import write_atomically
from harness.judge.records import RunResult, TickRecord
from harness.record import messages as msg

METADATA_NAME = "fossbot_hil_run"


@dataclass(frozen=True)
class RecordTopics:
    """Where each stream goes in the recording."""

    scan: str = "/scan"
    clock: str = "/clock"
    status: str = "/lidar_status"
    warning: str = "/obstacle_warning"
    pose: str = "/fossbot_hil/pose"
    verdict: str = "/fossbot_hil/verdict"
    seen_scan: str = "/fossbot_hil/seen_scan"  # the driver's scan, on serial links


def _ns(seconds: float) -> int:
    return max(0, round(seconds * 1e9))


def run_metadata(result: RunResult) -> dict[str, str]:
    """What replay and readers need to know about the run (MCAP metadata is str->str)."""
    return {
        "scenario": result.scenario,
        "link": result.link,
        "seed": str(result.seed),
        "threshold": repr(result.threshold),
        "faults": result.faults,
        "noise_sigma": repr(result.noise_sigma),
        "ok": str(result.ok).lower(),
        "ticks": str(len(result.records)),
        "failed_ticks": str(len(result.failed_ticks)),
        "error": result.error or "",
        "harness": f"fossbot-hil {__version__}",
    }


def _tick_messages(record: TickRecord, topics: RecordTopics) -> list[tuple[int, str, Any, str]]:
    """(log time ns, topic, message, type) for everything that happened in one tick."""
    t = record.t
    out: list[tuple[int, str, Any, str]] = [
        (_ns(t), topics.clock, msg.clock(t), msg.CLOCK),
        (_ns(t), topics.pose, msg.pose(t, record.x, record.y, record.yaw), msg.POSE),
    ]
    if record.delivery.delivered:  # a scan the link dropped was never injected
        out.append((_ns(t), topics.scan, msg.laser_scan(record.scan), msg.LASER_SCAN))
    answers = record.answers
    if answers.seen is not None:
        out.append((_ns(t), topics.seen_scan, msg.laser_scan(answers.seen), msg.LASER_SCAN))
    for item in [*answers.statuses, *answers.warnings, *answers.late]:
        when = _ns(t + item.after)
        if isinstance(item.value, bool):
            out.append((when, topics.warning, msg.boolean(item.value), msg.BOOL))
        else:
            out.append((when, topics.status, msg.string(item.value), msg.STRING))
    last = max(when for when, *_ in out)
    out.append((last, topics.verdict, msg.verdict(record.verdict), msg.VERDICT))
    return out


def recording_bytes(result: RunResult, topics: RecordTopics = RecordTopics()) -> bytes:
    """The whole recording in memory (a scenario's recording is a few megabytes at most)."""
    entries = [e for record in result.records for e in _tick_messages(record, topics)]
    entries.sort(key=lambda e: e[0])  # stable: within a time, tick order is kept
    buffer = io.BytesIO()
    writer = Writer(buffer, compression=CompressionType.ZSTD)
    writer.start(profile="ros2", library=f"fossbot-hil {__version__}")
    channels: dict[str, int] = {}
    schemas: dict[str, int] = {}

    def channel(topic: str, msgtype: str) -> int:
        if topic not in channels:
            if msgtype not in schemas:
                schemas[msgtype] = writer.register_schema(
                    name=msgtype, encoding="ros2msg", data=msg.schema_text(msgtype).encode()
                )
            channels[topic] = writer.register_channel(
                topic=topic, message_encoding="cdr", schema_id=schemas[msgtype]
            )
        return channels[topic]

    for sequence, (when, topic, message, msgtype) in enumerate(entries):
        writer.add_message(
            channel_id=channel(topic, msgtype),
            log_time=when,
            publish_time=when,
            data=msg.encode(message, msgtype),
            sequence=sequence,
        )
    writer.add_metadata(METADATA_NAME, run_metadata(result))
    writer.finish()
    return buffer.getvalue()


def write_recording(path: str | Path, result: RunResult) -> Path:
    """Write `result` as an MCAP file at `path`; a crash leaves no half file there."""
    return write_atomically(path, recording_bytes(result))
