"""The harness's own DDS participants announce themselves often (pure: no rclpy).

Fast DDS announces a participant a few times in its first half second, then every 3 s,
so a node that came up later (a fork server still importing) was matched only at the
next one: 3 s of start-up lost now and then. The harness's participants announce every
0.25 s (``fastdds_harness.xml``); the variable is set only while the harness creates
its own, so what it starts never sees it, and a user's profile file wins."""

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
