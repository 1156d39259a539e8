"""Hardware in the loop: the lab scenarios against a real FOSSBot board.

Run with the board's LIDAR input wired to a USB-UART (see docs/hil.md):
``pytest tests/hil --hil-port=/dev/ttyUSB0 --hil-domain-id 0``. Without
``--hil-port`` these tests skip and say so. Each test holds the port while
it runs, so under ``pytest -n N`` the workers take turns on the board.
"""

from __future__ import annotations

import pytest

from harness.pytest_plugin.hil import Hil
from harness.pytest_plugin.plugin import HilBoard, HilCase

pytestmark = [pytest.mark.hil, pytest.mark.ros, pytest.mark.timeout(900)]


@pytest.mark.hil_scenarios("approach_wall", "drive_past_10m", "out_of_range")
def test_lab_scenario_on_the_board(hil: Hil, hil_board: HilBoard, hil_case: HilCase) -> None:
    """The board's own driver and node, fed an emulated LIDAR, must pass the lab scenario."""
    result = hil.run(hil_case, **hil_board.run_options())
    assert result.ok, result.explanation
