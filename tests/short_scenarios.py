"""Short scenario files for tests that start many nodes for another point: what costs
there is each node's start and link, not the ticks. Each is shaped like the shipped
approach_wall (a wall ahead, the warning threshold crossed on the way), but the last,
nothing in range."""

from __future__ import annotations

from pathlib import Path

SHIPPED = Path(__file__).resolve().parents[1] / "harness" / "scenarios"

# approach_wall in 2.5 s instead of 9.5 s: a wall 0.6 m ahead, then standing still close.
WALL_AHEAD = """\
description: Drive at a wall 0.6 m ahead until very close, crossing the warning threshold.
lidar:
  preset: gazebo
obstacles:
  - type: wall
    start: [0.6, -2.0]
    end: [0.6, 2.0]
    thickness: 0.1
motion:
  segments:
    - linear: 0.2
      until: {obstacle_ahead_below: 0.2}
    - until: {duration: 0.5}
threshold: 0.5
"""
# approach_wall in 16 ticks instead of 95: a wall 0.8 m ahead, driven at until very close.
NEAR_WALL = """\
description: Drive at a near wall until very close, crossing the warning threshold.
lidar:
  preset: gazebo
obstacles:
  - {type: wall, start: [0.8, -2.0], end: [0.8, 2.0], thickness: 0.1}
motion:
  segments:
    - linear: 0.4
      until: {obstacle_ahead_below: 0.2}
threshold: 0.5
"""

# drive_past_10m in about 15 ticks: a wall behind, driven away from until beyond range_max
# (2 m here): its warning must clear, and then nothing is in range.
DRIVE_AWAY = """\
description: Start near a wall and drive away beyond range_max, where every beam reads +inf.
lidar:
  preset: gazebo
  range_max: 2.0
obstacles:
  - {type: wall, start: [-0.4, -3.0], end: [-0.4, 3.0], thickness: 0.1}
motion:
  segments:
    - linear: 2.0
      until: {distance: 2.5}
    - until: {duration: 0.5}
threshold: 0.5
"""


def nothing_in_range() -> str:
    """out_of_range with a sixth of its turn: every beam +inf, a few ticks."""
    text = (SHIPPED / "out_of_range.yaml").read_text()
    assert "until: {turn: 6.3}" in text
    return text.replace("turn: 6.3", "turn: 1.0")
