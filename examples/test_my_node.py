"""Scenario tests for a Lab 07 LIDAR node: copy this file into your project's tests/.

Run it against your node (the bundled reference node when no node is named):

    pytest test_my_node.py --hil-node "python3 my_lidar_node.py"
    pytest test_my_node.py -n 2      # in parallel: each run gets its own ROS domain

Each ``hil.run`` starts the node in its own process, drives the simulated
robot through one scenario, sends every LIDAR scan to the node over ROS 2
and judges its status String and Bool warning. docs/pytest.md has the rest.
"""

import pytest


def test_approach_wall(hil):
    """The lab's wall: the distance, the angle, and the warning once under 0.5 m."""
    result = hil.run("approach_wall")
    assert result.ok, result.explanation


def test_closer_threshold_with_noisy_ranges(hil):
    """The node must use its threshold parameter, and cope with range noise."""
    result = hil.run("approach_wall", threshold=0.4, faults="noisy")
    assert result.ok, result.explanation


def test_my_own_scenario(hil):
    """A scenario file next to this test (see docs/scenarios.md for the format)."""
    hil.run("narrow_corridor.yaml").check()  # check() raises with the explanation


@pytest.mark.hil_scenarios(
    "rotate_beside_wall", "obstacle_at_side", faults=["clean", "dropouts_nan"]
)
def test_lab_scenarios_under_faults(hil, hil_case):
    """One test per scenario and fault profile: test_..._faults[rotate_beside_wall-clean] ..."""
    result = hil.run(hil_case)
    assert result.ok, result.explanation


@pytest.mark.hil_scenarios()
def test_every_shipped_scenario(hil, hil_case):
    """No names: every scenario the harness ships, each with its own faults."""
    result = hil.run(hil_case)
    assert result.ok, result.explanation
