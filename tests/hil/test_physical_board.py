"""Hardware in the loop: the lab scenarios against a real FOSSBot board.

Run with the board's LIDAR input wired to a USB-UART (see docs/hil.md):
``pytest tests/hil --hil-port /dev/ttyUSB0 --hil-domain-id 0``. Without
``--hil-port`` these tests skip and say so.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from harness.plugin import HilBoard

pytestmark = [pytest.mark.hil, pytest.mark.ros, pytest.mark.timeout(600)]


@pytest.mark.parametrize("scenario", ["approach_wall", "drive_past_10m", "out_of_range"])
def test_lab_scenario_on_the_board(hil_board: HilBoard, scenario: str) -> None:
    """The board's own driver and node, fed an emulated LIDAR, must pass the lab scenario."""
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            scenario,
            "--link",
            hil_board.link,
            "--port",
            hil_board.port,
            "--ros-network",
            "--domain-id",
            str(hil_board.domain_id),
        ],
        capture_output=True,
        text=True,
        timeout=540,
    )
    assert done.returncode == 0, done.stdout + done.stderr
