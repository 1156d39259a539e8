"""Splitting sample streams into revolutions: RPLIDAR start flags, LD angle wraps."""

from __future__ import annotations

import numpy as np
import pytest
from fossbot_lidar_driver.revolutions import LdRevolutionSplitter, RplidarRevolutionSplitter


def test_rplidar_turn_is_complete_only_when_the_next_start_flag_arrives() -> None:
    """Samples before the first start are dropped; each start closes the turn before it."""
    splitter = RplidarRevolutionSplitter()
    assert splitter.add(False, 10, 350.0, 500.0, 0.00) is None  # partial lead-in
    assert splitter.add(True, 10, 0.5, 1000.0, 0.10) is None  # turn 1 starts
    assert splitter.add(False, 0, 180.0, 0.0, 0.15) is None
    turn = splitter.add(True, 12, 0.2, 900.0, 0.30)  # turn 2 starts: turn 1 is done
    assert turn is not None
    assert splitter.dropped == 1
    assert turn.angles_deg.tolist() == [0.5, 180.0]
    assert turn.distances_mm.tolist() == [1000.0, 0.0]
    assert turn.intensities.tolist() == [10, 0]
    assert (turn.start, turn.end, len(turn)) == (0.10, 0.30, 2)
    assert turn.duration == pytest.approx(0.20)


def test_ld_turn_ends_where_the_angle_wraps_inside_a_packet() -> None:
    """The wrap splits a packet: points before it end the turn, the rest start the next."""
    splitter = LdRevolutionSplitter()
    zeros = np.zeros(4)
    assert splitter.add_packet(np.array([350.0, 355.0, 1.0, 5.0]), zeros, zeros, 1.0) == []
    assert splitter.dropped == 2  # before the first wrap
    assert splitter.add_packet(np.array([120.0, 240.0, 300.0, 359.0]), zeros, zeros, 1.1) == []
    turns = splitter.add_packet(
        np.array([359.5, 2.0, 3.0, 4.0]), np.array([7, 8, 9, 10]), np.array([1, 2, 3, 4]), 1.2
    )
    assert len(turns) == 1
    turn = turns[0]
    assert turn.angles_deg.tolist() == [1.0, 5.0, 120.0, 240.0, 300.0, 359.0, 359.5]
    assert turn.distances_mm[-1] == 7 and turn.intensities[-1] == 1
    assert (turn.start, turn.end) == (1.0, 1.2)


def test_ld_small_backward_steps_are_not_wraps() -> None:
    """Jitter (an angle a little below the last) does not end a turn."""
    splitter = LdRevolutionSplitter()
    zeros = np.zeros(3)
    splitter.add_packet(np.array([359.0, 1.0, 0.9]), zeros, zeros, 0.0)
    assert splitter.add_packet(np.array([90.0, 89.5, 200.0]), zeros, zeros, 0.05) == []
    assert len(splitter.add_packet(np.array([359.9, 0.1, 0.2]), zeros, zeros, 0.1)) == 1
