"""ldlidar_node as a real process on a real pty, fed hand-made LD06/LD19 packets."""

from __future__ import annotations

import math
import re
import signal

import numpy as np
import pytest
from driver_checks import (
    check_missing_port_exits_2_with_one_line,
    check_port_vanishing_exits_1_promptly,
)
from driver_wire import BURST_PERIOD, POINTS_PER_TURN, LdStreamer, burst, point

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]

MODULE = "ldlidar_node"


# The hand-made points sit on the 0.8-degree grid from the device's zero: read
# them as a device whose zero points forward (the default's -90 deg is 112.5 bins).
FORWARD_MAPPING = ("-p", "invert:=true", "-p", "angle_offset_deg:=0.0")


def expected_ranges() -> np.ndarray:
    """Bin k holds the point at clockwise 0.8 * m degrees with m = (450 - k) % 450."""
    ranges = np.empty(POINTS_PER_TURN, dtype=np.float32)
    for k in range(POINTS_PER_TURN):
        distance, intensity = point((POINTS_PER_TURN - k) % POINTS_PER_TURN)
        ranges[k] = math.nan if distance == 0 and intensity == 0 else distance / 1000.0
    return ranges


def test_scans_follow_the_vendor_conventions_on_450_bins(pty, start_driver, scan_probe) -> None:
    """Every turn is one scan: 450 CCW bins, NaN for no return, other readings as sent."""
    LdStreamer(pty, burst, BURST_PERIOD).start()
    driver = start_driver(MODULE, "-p", f"port:={pty.name}", *FORWARD_MAPPING)
    scans = scan_probe().wait_scans(3, driver)
    increment = 2 * math.pi / POINTS_PER_TURN
    expected = expected_ranges()
    assert np.isnan(expected).sum() == 9 and (expected == 0.0).sum() == 9
    for scan in scans:
        assert scan.header.frame_id == "lidar_scan_frame"
        assert scan.angle_min == 0.0
        assert scan.angle_increment == pytest.approx(increment, rel=1e-6)
        assert scan.angle_max == pytest.approx(2 * math.pi - increment, rel=1e-6)
        assert (scan.range_min, scan.range_max) == (pytest.approx(0.02), pytest.approx(25.0))
        np.testing.assert_array_equal(np.frombuffer(scan.ranges, np.float32), expected)
        # Measured from packet arrival, as the vendor driver does: a busy host that
        # reads two bursts at once shortens it, so only its bounds are certain.
        assert 0.0 <= scan.scan_time < 1.0
        assert scan.time_increment == pytest.approx(scan.scan_time / POINTS_PER_TURN, rel=1e-5)
    assert driver.stop() == 0


def test_sigterm_exits_0(pty, start_driver, scan_probe) -> None:
    """SIGTERM while streaming: exit 0, no traceback."""
    LdStreamer(pty, burst, BURST_PERIOD).start()
    driver = start_driver(MODULE, "-p", f"port:={pty.name}")
    scan_probe().wait_scans(1, driver)
    assert driver.stop(signal.SIGTERM) == 0
    driver.assert_no_traceback()


def test_port_that_cannot_be_opened_exits_2_with_one_line(start_driver) -> None:
    """No such device: exit 2 and exactly one log line, naming the port."""
    check_missing_port_exits_2_with_one_line(start_driver, MODULE)


def test_port_vanishing_mid_run_exits_1_promptly(pty, start_driver, scan_probe) -> None:
    """Closing the pty ends the driver within about a second, exit 1."""
    LdStreamer(pty, burst, BURST_PERIOD).start()
    check_port_vanishing_exits_1_promptly(pty, start_driver, scan_probe, MODULE)


def test_noise_without_packets_exits_1_after_the_timeout(pty, start_driver) -> None:
    """Bytes that never make a valid packet count as silence: exit 1 after `timeout`."""
    noise = bytes([0x54, 0x2C]) + bytes(range(60))
    LdStreamer(pty, lambda number: noise, 0.02).start()
    driver = start_driver(MODULE, "-p", f"port:={pty.name}", "-p", "timeout:=0.5")
    assert driver.wait() == 1
    stderr = driver.stderr()
    assert "no valid packet for 0.5 s" in stderr
    counted = re.search(r"\((\d+) CRC errors", stderr)  # "30 CRC errors" holds "0 CRC errors"
    assert counted is not None and int(counted.group(1)) > 0, stderr
    driver.assert_no_traceback()
