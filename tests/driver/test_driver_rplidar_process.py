"""rplidar_node as a real process on a real pty, answered by a scripted RPLIDAR.

The driver talks through the PyPI `rplidar` package; the test side plays the
device with hand-written Slamtec replies and reads /scan over rclpy.
"""

from __future__ import annotations

import math
import signal
import time

import numpy as np
import pytest
import rplidar  # noqa: F401  (the `test` extra's; the driver under test talks through it)
from driver_checks import (
    check_missing_port_exits_2_with_one_line,
    check_port_vanishing_exits_1_promptly,
)
from driver_wire import (
    CMD_GET_HEALTH,
    CMD_GET_INFO,
    CMD_MOTOR_PWM,
    CMD_SCAN,
    CMD_STOP,
    RplidarResponder,
    rp_revolution,
    rp_sample,
)

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]

INF = math.inf
MODULE = "rplidar_node"

# (quality, device angle clockwise in degrees, distance in mm); the first
# sample carries the start flag. Comments: the CCW bin of a device whose zero
# points forward (invert, offset 0) and what it must hold; the driver's default
# (the v2 bridge's invert, -90) puts each of them 90 bins clockwise.
REVOLUTION = [
    (20, 0.0, 1000.0),  # bin 0: 1.0 ...
    (20, 359.6, 900.0),  # ... beaten across the wrap by 0.9 (ccw 0.41 deg)
    (20, 90.0, 500.0),  # bin 270: clockwise 90 is counter-clockwise 270
    (20, 270.25, 800.0),  # bin 90 (ccw 89.75) ...
    (20, 269.75, 700.0),  # ... and ccw 90.25: the nearer one, 0.7, wins
    (20, 45.0, 0.0),  # bin 315: no return -> +inf
    (20, 180.0, 100.0),  # bin 180: 0.1 m < range_min -> dropped, +inf
    (20, 200.0, 13000.0),  # bin 160: 13 m > range_max -> dropped, +inf
    (20, 10.0, 12000.0),  # bin 350: exactly range_max is kept
    (20, 300.0, 150.0),  # bin 60: exactly range_min is kept
    (20, 330.0, 1234.25),  # bin 30: the agent's 0.1 mm rounding: 1.2342
    (0, 120.0, 2000.0),  # bin 240: quality 0 with a distance is a return
]
EXPECTED_FINITE = {0: 0.9, 270: 0.5, 90: 0.7, 350: 12.0, 60: 0.15, 30: 1.2342, 240: 2.0}
# Before the first start flag: a partial turn the driver must drop (bin 355).
LEAD_IN = rp_sample(False, 20, 5.0, 3000.0) + rp_sample(False, 20, 6.0, 3000.0)


V2_OFFSET_DEG = -90  # the driver's default angle_offset_deg: the v2 bridge's


def expected_ranges(offset_deg: int = V2_OFFSET_DEG) -> np.ndarray:
    """The scan of REVOLUTION for a driver with `invert` and this angle_offset_deg."""
    ranges = np.full(360, INF, dtype=np.float32)
    for index, value in EXPECTED_FINITE.items():
        ranges[(index + offset_deg) % 360] = value
    return ranges


def start_device(pty, **kwargs) -> RplidarResponder:
    return RplidarResponder(pty, rp_revolution(REVOLUTION), lead_in=LEAD_IN, **kwargs).start()


def test_one_scan_per_revolution_in_the_lab_robots_layout(pty, start_driver, scan_probe) -> None:
    """Bins (the v2 bridge's mapping by default), filtering, header and timing of a scripted A1."""
    device = start_device(pty, period=0.05)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}")
    probe = scan_probe()
    scans = probe.wait_scans(3, driver)

    increment = 2 * math.pi / 360
    for scan in scans:
        assert scan.header.frame_id == "lidar_scan_frame"
        assert scan.angle_min == 0.0
        assert scan.angle_increment == pytest.approx(increment, rel=1e-6)
        assert scan.angle_max == pytest.approx(2 * math.pi - increment, rel=1e-6)
        assert (scan.range_min, scan.range_max) == (pytest.approx(0.15), pytest.approx(12.0))
        ranges = np.frombuffer(scan.ranges, np.float32)
        np.testing.assert_array_equal(ranges, expected_ranges())
        # Paced every 50 ms: the measured turn, not a constant.
        # Measured from sample arrival, as the vendor driver does: a busy host that
        # reads two bursts at once shortens it, so only its bounds are certain.
        assert 0.0 <= scan.scan_time < 1.0
        assert scan.time_increment == pytest.approx(scan.scan_time / 360, rel=1e-5)
        assert abs(scan.header.stamp.sec - time.time()) < 30
    # What rplidar 0.9.2 asks, in order (motor PWM from the constructor and again at scan start).
    assert device.commands()[:6] == [
        CMD_MOTOR_PWM,
        CMD_GET_INFO,
        CMD_GET_HEALTH,
        CMD_MOTOR_PWM,
        CMD_GET_HEALTH,
        CMD_SCAN,
    ]
    assert driver.stop() == 0


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_stops_scan_and_motor_and_exits_0(pty, start_driver, scan_probe, sig) -> None:
    """A stop sends STOP and MOTOR_PWM 0, closes the port, exits 0 without a traceback."""
    device = start_device(pty)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}")
    scan_probe().wait_scans(1, driver)
    started = time.monotonic()
    assert driver.stop(sig) == 0
    assert time.monotonic() - started < 3.0
    after_scan = device.requests[device.commands().index(CMD_SCAN) + 1 :]
    assert (CMD_STOP, b"") in after_scan
    assert (CMD_MOTOR_PWM, b"\x00\x00") in after_scan
    driver.assert_no_traceback()


def test_port_that_cannot_be_opened_exits_2_with_one_line(start_driver) -> None:
    """No such device: exit 2 and exactly one log line, naming the port."""
    check_missing_port_exits_2_with_one_line(start_driver, MODULE)


def test_port_vanishing_mid_run_exits_1_promptly(pty, start_driver, scan_probe) -> None:
    """Unplugging (closing the pty) ends the driver within about a second, exit 1."""
    start_device(pty)
    check_port_vanishing_exits_1_promptly(pty, start_driver, scan_probe, MODULE)


def test_health_error_exits_1_before_scanning(pty, start_driver) -> None:
    """GET_HEALTH says Error: the driver logs it and exits 1 without asking for a scan."""
    device = start_device(pty, health=2)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}")
    assert driver.wait() == 1
    assert "health: Error" in driver.stderr()
    assert CMD_SCAN not in device.commands()
    driver.assert_no_traceback()


def test_silent_device_exits_1_after_the_timeout(pty, start_driver) -> None:
    """A device that acknowledges SCAN and then sends nothing: exit 1 after `timeout`."""
    start_device(pty, send_samples=False)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}", "-p", "timeout:=0.5")
    assert driver.wait() == 1
    assert "no complete reply within 0.5 s" in driver.stderr()
    driver.assert_no_traceback()


def test_bad_parameter_exits_2(start_driver) -> None:
    """An unusable parameter is a configuration error: one FATAL line, exit 2."""
    driver = start_driver(MODULE, "-p", "bins:=0")
    assert driver.wait() == 2
    assert "configuration error: bins must be positive" in driver.stderr()
    driver.assert_no_traceback()


def test_sparse_revolutions_are_skipped_with_min_returns(pty, start_driver, scan_probe) -> None:
    """min_returns:=12 never publishes REVOLUTION, which has 11 returns (distance > 0)."""
    start_device(pty, period=0.02)
    skipping = start_driver(MODULE, "-p", f"port:={pty.name}", "-p", "min_returns:=12")
    probe = scan_probe()
    deadline = time.monotonic() + 1.5
    while time.monotonic() < deadline:
        skipping.check_alive()
        probe.executor.spin_once(timeout_sec=0.05)
    assert probe.scans == []
    assert skipping.stop() == 0


def test_stamps_follow_sim_time(pty, start_driver, scan_probe) -> None:
    """With use_sim_time the stamp is /clock's time, not the wall clock."""
    from rosgraph_msgs.msg import Clock

    start_device(pty)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}", "-p", "use_sim_time:=true")
    probe = scan_probe()
    clock = probe.node.create_publisher(Clock, "/clock", 10)
    message = Clock()
    message.clock.sec = 4242
    deadline = time.monotonic() + 10.0
    while not any(scan.header.stamp.sec == 4242 for scan in probe.scans):
        if time.monotonic() > deadline:
            stamps = [scan.header.stamp.sec for scan in probe.scans]
            pytest.fail(f"no scan stamped at /clock's 4242 s; stamps {stamps[-5:]}")
        driver.check_alive()
        clock.publish(message)
        probe.executor.spin_once(timeout_sec=0.05)
    assert driver.stop() == 0


def test_damaged_sample_restarts_the_scan_and_publishing_goes_on(
    pty, start_driver, scan_probe
) -> None:
    """A sample with a bad check bit: STOP, a new SCAN, and scans keep coming."""
    device = start_device(pty, period=0.03, corrupt_revolution=5)
    driver = start_driver(MODULE, "-p", f"port:={pty.name}")
    probe = scan_probe()
    deadline = time.monotonic() + 10.0
    while device.commands().count(CMD_SCAN) < 2:
        assert time.monotonic() < deadline, driver.stderr()
        driver.check_alive()
        probe.executor.spin_once(timeout_sec=0.05)
    before = len(probe.scans)
    probe.wait_scans(before + 3, driver)
    commands = device.commands()
    first_scan = commands.index(CMD_SCAN)
    assert CMD_STOP in commands[first_scan:]
    assert "restarting the scan (1/3)" in driver.stderr()
    for scan in probe.scans:
        np.testing.assert_array_equal(np.frombuffer(scan.ranges, np.float32), expected_ranges())
    assert driver.stop() == 0
    driver.assert_no_traceback()
