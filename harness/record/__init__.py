"""Recordings: one MCAP file per scenario run, and reading scans back for replay.

Pure Python (mcap + rosbags): no ROS install is needed to write or read
them, and Foxglove, ``ros2 bag``, the ``mcap`` tools and rosbags read them.
"""

from harness.record.reader import RecordedScans, read_scans
from harness.record.writer import write_recording

__all__ = ["RecordedScans", "read_scans", "write_recording"]
