"""The beams an ``obstacle_ahead_*`` condition looks at (pure: numpy only).

Scenario checks refuse a condition this LIDAR has no beam for; the motion
script evaluates the condition on those beams once per revolution.
"""

from __future__ import annotations

import math

import numpy as np

from harness.lidar.spec import LidarSpec

AHEAD_HALF_WIDTH = math.radians(10.0)  # obstacle_ahead_* look within +-10 deg of +x


def ahead_mask(spec: LidarSpec, half_width: float = AHEAD_HALF_WIDTH) -> np.ndarray:
    """Beams within +-half_width of the LIDAR's forward axis (any angle_min)."""
    angles = spec.angle_min + np.arange(spec.samples) * spec.angle_increment
    wrapped = np.remainder(angles + np.pi, 2.0 * np.pi) - np.pi
    return np.abs(wrapped) <= half_width + 1e-9
