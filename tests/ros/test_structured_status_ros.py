"""A right node whose status is JSON passes over real DDS, the scans with nothing in
range included (json.dumps writes Infinity there). The three formats over the whole
default suite in process: tests/test_status_structured_e2e.py."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

NODE = Path(__file__).parent / "structured_status_node.py"


def test_json_status_passes_over_ros2() -> None:
    """approach_wall, out_of_range and drive_past_10m, with a JSON status."""
    scenarios = ("approach_wall", "out_of_range", "drive_past_10m")
    done = fossbot_hil("run", *scenarios, "--node", f"{sys.executable} {NODE} json")
    assert done.returncode == 0, done.stdout + done.stderr
    for name in scenarios:
        assert f"{name} " in done.stdout
    assert "FAIL" not in done.stdout
