"""Unit tests of the pure scan logic: no ROS graph needed, only numpy."""

import array
import math

import pytest

try:  # colcon test: the package is installed under its own name.
    from fossbot_lidar_processing.scan_logic import analyse_scan, status_text
except ImportError:  # the fossbot-hil harness ships it as harness.reference.
    from harness.reference.scan_logic import analyse_scan, status_text

INF = math.inf


def scan(ranges, threshold=0.5):
    """Analyse ``ranges`` with the Gazebo-like header: -pi, 1 deg, 0.12-12 m."""
    return analyse_scan(ranges, -math.pi, math.radians(1.0), 0.12, 12.0, threshold)


def test_far_from_everything_is_no_obstacle():
    """The lab's pitfall: all +inf means no obstacle, not a distance of inf."""
    report = scan(array.array('f', [INF] * 360))
    assert not report.obstacle and not report.warning
    assert status_text(report) == 'No obstacle detected'


def test_invalid_readings_are_ignored():
    """-inf, NaN, 0.0, below range_min and above range_max never win."""
    report = scan([-INF, math.nan, 0.0, 0.05, 12.5, 3.0])
    assert (report.distance, report.index) == (3.0, 5)


def test_angle_is_angle_min_plus_index_times_increment():
    """The angle follows the lab's formula, starting at angle_min = -pi."""
    ranges = [INF] * 360
    ranges[90] = 0.842
    report = scan(ranges)
    assert report.angle == pytest.approx(-math.pi + 90 * math.radians(1.0))


def test_warning_is_strictly_below_threshold():
    """A reading exactly at the threshold does not warn; just below does."""
    assert not scan([0.5], threshold=0.5).warning
    assert scan([0.499], threshold=0.5).warning


def test_status_text_has_distance_then_angle():
    """The status names the distance first and the angle second."""
    report = analyse_scan([0.842], 0.524, 0.0, 0.1, 12.0, 0.5)
    assert status_text(report) == 'Min distance: 0.842 m, angle: 0.524 rad'
