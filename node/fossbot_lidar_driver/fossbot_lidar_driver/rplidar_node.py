"""
RPLIDAR A1 on a serial port to sensor_msgs/LaserScan, as the FOSSBot v2 robot publishes it.

Reads the device with the PyPI ``rplidar`` package (0.9.2, SkoltechRobotics)
and publishes one scan per revolution: ``bins`` bins over [0, 2*pi), empty
bins +inf, returns outside [range_min, range_max] dropped, the nearest
return kept per bin. Angles follow the lab robot's bridge by default
(``invert`` true, ``angle_offset_deg`` -90: the v2's A1 points its zero to
the robot's right), so straight ahead is angle 0. Run it as ``ros2 run
fossbot_lidar_driver rplidar_node --ros-args -p port:=/dev/ttyUSB0``; see
the package README for the angle mapping and how it compares with the lab
robot's bridge.
"""

from __future__ import annotations

import errno
import logging
import sys
import time
from typing import Any

from rclpy.impl.rcutils_logger import RcutilsLogger
import rplidar
from serial import SerialException

from .binning import rplidar_ranges
from .driver_node import (
    ConfigError,
    DeviceError,
    DriverNode,
    PortError,
    run,
    StopRequest,
)
from .revolutions import Revolution, RplidarRevolutionSplitter

__all__ = ['DEFAULTS', 'NODE_NAME', 'main']

# The lab bridge's node name, so `ros2 param get /fossbot_lidar ...` works alike.
NODE_NAME = 'fossbot_lidar'
QOS_DEPTH = 5  # the bridge: reliable, keep-last 5
DEFAULTS: dict[str, Any] = {
    'port': '/dev/ttyUSB0',
    'baudrate': 115200,
    'frame_id': 'lidar_scan_frame',
    'scan_topic': '/scan',
    'range_min': 0.15,
    'range_max': 12.0,
    'bins': 360,
    'timeout': 1.0,
    # The FOSSBot v2 bridge's mapping: the A1's zero points to the robot's right.
    'invert': True,
    'angle_offset_deg': -90.0,
    'bin_mode': 'nearest',
    # rplidar 0.9.2 discards the input buffer beyond this many samples (0: never).
    'max_buf_meas': 500,
    # Publish a revolution only with at least this many returns (the lab's
    # agent uses rplidar's iter_scans, which skips turns of 5 or fewer: 6).
    'min_returns': 0,
}
# A pty has no modem control lines: setting DTR there fails with one of these.
NO_MODEM_LINES = (errno.ENOTTY, errno.EINVAL)
SERIAL_ERRORS = (rplidar.RPLidarException, SerialException, OSError)
# rplidar's messages for a reply cut short by the read timeout.
SHORT_READS = ('Wrong body size', 'Descriptor length mismatch')
MAX_RESTARTS = 3
RESTART_PAUSE = 0.05  # after STOP, for samples already on the line to arrive


class _Lidar(rplidar.RPLidar):
    """
    rplidar.RPLidar that tolerates a port without DTR and can be woken from a read.

    The A1 runs its motor while DTR is low; the library sets DTR in
    start_motor/stop_motor, which raises on a pty (the harness's emulated
    device). Here DTR is set where the port has it, and the rest of the
    library's motor sequence (the A2's MOTOR_PWM request) is sent either way,
    so the device sees the same requests on a pty as on a USB adapter.
    """

    def __init__(self, port: str, baudrate: int, timeout: float, logger: RcutilsLogger) -> None:
        """Open the port and start the motor (the library's constructor does both)."""
        self._ros_logger = logger
        self._dtr_missing = False
        super().__init__(port, baudrate, timeout)

    def connect(self) -> None:
        """Open the port; a port that cannot be opened is a PortError."""
        try:
            super().connect()
        except rplidar.RPLidarException as err:
            raise PortError(f'cannot open {self.port}: {err}') from err

    def _set_dtr(self, level: bool) -> None:
        try:
            self._serial_port.dtr = level
        except OSError as err:
            if err.errno not in NO_MODEM_LINES:
                raise
            if not self._dtr_missing:
                self._dtr_missing = True
                self._ros_logger.info(f'{self.port} has no DTR line (a pty?): not driving it')

    def start_motor(self) -> None:
        """Start the motor: DTR low (A1), then MOTOR_PWM (A2), as the library does."""
        self._set_dtr(False)
        self.set_pwm(rplidar.DEFAULT_MOTOR_PWM)
        self.motor_running = True

    def stop_motor(self) -> None:
        """Stop the motor: MOTOR_PWM 0 (A2), then DTR high (A1), as the library does."""
        self.set_pwm(0)
        time.sleep(0.001)
        self._set_dtr(True)
        self.motor_running = False

    def cancel_read(self) -> None:
        """Make a blocking read return now (its caller then sees a short reply)."""
        port = self._serial_port
        if port is not None and port.is_open:
            port.cancel_read()


class _ForwardToRos(logging.Handler):
    """Send the rplidar library's warnings (e.g. a full input buffer) to the ROS log."""

    def __init__(self, logger: RcutilsLogger) -> None:
        """Forward WARNING and above to ``logger``."""
        super().__init__(logging.WARNING)
        self._logger = logger

    def emit(self, record: logging.LogRecord) -> None:
        """Log one record at the matching ROS severity."""
        message = f'rplidar: {record.getMessage()}'
        if record.levelno >= logging.ERROR:
            self._logger.error(message)
        else:
            self._logger.warning(message)


def _describe(err: BaseException, timeout: float) -> str:
    """Return a one-line reason, saying what a short read means."""
    text = str(err) or type(err).__name__
    if text in SHORT_READS:
        return f'no complete reply within {timeout} s ({text})'
    return text


def _stream(
    lidar: _Lidar, node: DriverNode, stop: StopRequest, max_buf_meas: int, min_returns: int
) -> None:
    """
    Publish revolutions until stopped; restart the scan when the stream is out of step.

    rplidar 0.9.2 raises on a sample with bad flags or check bit (a byte lost
    or damaged on the line) and its generator is then finished. The lab
    robot's agent reconnects in that case; here the scan is stopped, the
    input drained and the scan started again, up to MAX_RESTARTS times in a
    row without a revolution in between. A short read (silence) is not
    retried: it is the device failing.
    """
    logger = node.get_logger()
    failures = 0
    while not stop.requested:
        splitter = RplidarRevolutionSplitter()
        try:
            for new_scan, quality, angle, distance in lidar.iter_measurments(max_buf_meas):
                if stop.requested:
                    return
                revolution = splitter.add(new_scan, quality, angle, distance, time.monotonic())
                if revolution is not None:
                    _publish(node, revolution, min_returns)
                    failures = 0
        except rplidar.RPLidarException as err:
            if stop.requested or str(err) in SHORT_READS or failures >= MAX_RESTARTS:
                raise
            failures += 1
            logger.warning(
                f'RPLIDAR stream out of step ({err}): restarting the scan '
                f'({failures}/{MAX_RESTARTS})'
            )
            lidar.stop()
            time.sleep(RESTART_PAUSE)
            lidar.clear_input()


def _shut_down(lidar: _Lidar, logger: RcutilsLogger) -> None:
    """Stop scanning and the motor, then close the port, each as far as the port allows."""
    for step in (lidar.stop, lidar.stop_motor, lidar.disconnect):
        try:
            step()
        except SERIAL_ERRORS as err:
            logger.debug(f'{step.__name__}: {err}')


def _check_device(lidar: _Lidar, node: DriverNode) -> None:
    """Log GET_INFO and GET_HEALTH; a health of Error is a DeviceError."""
    logger = node.get_logger()
    info = lidar.get_info()
    logger.info(
        f'RPLIDAR model {info["model"]}, firmware {info["firmware"][0]}.{info["firmware"][1]}, '
        f'hardware {info["hardware"]}, serial {info["serialnumber"]}'
    )
    status, code = lidar.get_health()
    if status == 'Error':
        raise DeviceError(f'RPLIDAR health: Error (code {code:#06x}); power-cycle the device')
    if status == 'Warning':
        logger.warning(f'RPLIDAR health: Warning (code {code:#06x})')
    else:
        logger.info(f'RPLIDAR health: {status}')


def _publish(node: DriverNode, revolution: Revolution, min_returns: int) -> None:
    """Publish one revolution, unless it has fewer returns than ``min_returns``."""
    if int((revolution.distances_mm > 0).sum()) < min_returns:
        return
    s = node.settings
    ranges = rplidar_ranges(
        revolution.angles_deg,
        revolution.distances_mm,
        s.bins,
        range_min=s.range_min,
        range_max=s.range_max,
        invert=s.invert,
        angle_offset_deg=s.angle_offset_deg,
        mode=s.bin_mode,
    )
    node.publish_scan(ranges, revolution.duration, len(revolution))


def serve(node: DriverNode, stop: StopRequest) -> None:
    """Open the LIDAR, check it, and publish revolutions until stopped or failed."""
    s = node.settings
    max_buf_meas = node.declare_extra('max_buf_meas', 'input buffer limit in samples (0: none)')
    min_returns = node.declare_extra('min_returns', 'skip revolutions with fewer returns')
    if max_buf_meas < 0 or min_returns < 0:
        raise ConfigError('max_buf_meas and min_returns must be >= 0')
    if not hasattr(rplidar.RPLidar, 'iter_measurments'):
        raise ConfigError(
            'the installed `rplidar` module is not PyPI rplidar 0.9.2 (no iter_measurments); '
            'rplidar-roboticia and other forks install a module of the same name'
        )
    if stop.requested:
        return
    logger = node.get_logger()
    library_log = logging.getLogger('rplidar')
    library_log.setLevel(logging.WARNING)
    library_log.propagate = False
    library_log.addHandler(_ForwardToRos(logger))
    lidar = None
    try:
        lidar = _Lidar(s.port, s.baudrate, s.timeout, logger)
        stop.add_canceller(lidar.cancel_read)
        _check_device(lidar, node)
        logger.info(
            f'{s.port} at {s.baudrate} baud -> {s.scan_topic} ({s.bins} bins, frame '
            f'{s.frame_id}, {s.range_min}-{s.range_max} m)'
        )
        _stream(lidar, node, stop, max_buf_meas, min_returns)
    except SERIAL_ERRORS as err:
        if stop.requested:
            return
        raise DeviceError(f'RPLIDAR on {s.port}: {_describe(err, s.timeout)}') from err
    finally:
        if lidar is not None:
            _shut_down(lidar, logger)


def main(args: list[str] | None = None) -> int:
    """Run the RPLIDAR driver; return the exit code (0 stopped, 1 device error, 2 config)."""
    return run(NODE_NAME, lambda: DriverNode(NODE_NAME, DEFAULTS, QOS_DEPTH), serve, args)


if __name__ == '__main__':
    sys.exit(main())
