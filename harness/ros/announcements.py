"""The harness's own DDS participants announce themselves often (pure: no rclpy).

Fast DDS announces a new participant a few times in its first half second,
then every 3 s. A node that comes up after the harness's participant has
stopped its first announcements (a fork server still importing, a slow
student import) was matched only at the next one: 3 s of a scenario's
start-up spent waiting, now and then. The harness's participants announce
every 0.25 s instead (``fastdds_harness.xml``, Fast DDS's default-profile
file, read as a process creates its first participant). The variable is set
only while the harness creates its own participants, so nodes, boards and
builds it starts never see it, and a user's own profile file wins.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

PROFILE = Path(__file__).with_name("fastdds_harness.xml")
SETTINGS = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")


@contextlib.contextmanager
def harness_announcements() -> Iterator[None]:
    """Within it, a new participant of this process uses the harness's profile (unless
    the user named a profile file of their own)."""
    if any(name in os.environ for name in SETTINGS) or not PROFILE.is_file():
        yield
        return
    os.environ[SETTINGS[0]] = str(PROFILE)
    try:
        yield
    finally:
        os.environ.pop(SETTINGS[0], None)
