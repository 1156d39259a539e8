"""Device angles to LaserScan bins (numpy only, no ROS)."""

import math

from fossbot_lidar_driver.binning import bin_indices, rplidar_ranges
import numpy as np


def test_clockwise_degrees_to_counter_clockwise_bins():
    """Clockwise 90 is bin 270 of 360; clockwise 270 is bin 90."""
    assert bin_indices(np.array([0.0, 90.0, 270.0]), 360).tolist() == [0, 270, 90]


def test_rplidar_keeps_the_nearest_return_in_range():
    """No return and out-of-limit readings leave +inf; the nearer of two wins."""
    angles = np.array([90.0, 90.2, 180.0, 45.0])
    distances = np.array([800.0, 700.0, 100.0, 0.0])
    ranges = rplidar_ranges(angles, distances, 360, range_min=0.15, range_max=12.0)
    assert ranges[270] == 0.7
    assert math.isinf(ranges[180]) and math.isinf(ranges[315])


def test_the_v2_mapping_shows_the_a1_in_the_robots_frame():
    """invert, -90 (the v2 bridge, the nodes' default): the A1's 270 is ahead, 180 left."""
    angles = np.array([270.0, 180.0, 0.0, 90.0])
    bins = bin_indices(angles, 360, invert=True, angle_offset_deg=-90.0)
    assert bins.tolist() == [0, 90, 270, 180]
