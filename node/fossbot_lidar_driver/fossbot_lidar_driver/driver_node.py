"""
What both LIDAR drivers share: parameters, the LaserScan, exit codes, signals.

A driver is a ``serve(node, stop)`` function that owns the serial port in
the main thread and publishes one scan per revolution; ``run`` wraps it in
rclpy, spins the node (parameter services, /clock for use_sim_time) in a
background thread and turns every way of ending into an exit code:

- 0: stopped by SIGINT/SIGTERM (the device stopped and disconnected);
- 1: the device failed at run time (port gone, silent, bad reply, health);
- 2: configuration: a bad parameter, or a port that cannot be opened.

Errors are logged as one line each, with no traceback.
"""

from __future__ import annotations

import array
from collections.abc import Callable
from dataclasses import dataclass
import math
import signal
import threading
from typing import Any

import numpy as np
import rcl_interfaces.msg
import rclpy
from rclpy.exceptions import (
    InvalidParameterTypeException,
    InvalidTopicNameException,
    ParameterException,
)
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import LaserScan

from .binning import BIN_MODES, scan_angle_max, scan_increment

__all__ = [
    'EXIT_CONFIG_ERROR',
    'EXIT_DEVICE_ERROR',
    'EXIT_OK',
    'ConfigError',
    'DeviceError',
    'DriverNode',
    'DriverSettings',
    'PortError',
    'StopRequest',
    'run',
]

EXIT_OK = 0
EXIT_DEVICE_ERROR = 1
EXIT_CONFIG_ERROR = 2


class ConfigError(ValueError):
    """A parameter value the driver cannot run with."""


class DeviceError(RuntimeError):
    """The LIDAR or its port failed while running."""


class PortError(RuntimeError):
    """The serial port could not be opened (a configuration error: exit 2)."""


@dataclass(frozen=True)
class DriverSettings:
    """The parameters every driver reads, checked."""

    port: str
    baudrate: int
    frame_id: str
    scan_topic: str
    range_min: float
    range_max: float
    bins: int
    timeout: float
    invert: bool
    angle_offset_deg: float
    bin_mode: str


class StopRequest:
    """Set by a signal; wakes a blocking serial read through its cancellers."""

    def __init__(self) -> None:
        """Start with no stop requested and nothing to cancel."""
        self.requested = False
        self._cancellers: list[Callable[[], None]] = []

    def add_canceller(self, cancel: Callable[[], None]) -> None:
        """Call ``cancel`` (e.g. ``serial.Serial.cancel_read``) when a stop comes."""
        self._cancellers.append(cancel)
        if self.requested:
            cancel()

    def request(self) -> None:
        """Note the stop and interrupt whatever read is waiting."""
        self.requested = True
        for cancel in self._cancellers:
            try:
                cancel()
            except (OSError, ValueError, AttributeError, TypeError):
                pass  # the port is already closed: nothing is waiting on it


def _descriptor(description: str, *, dynamic: bool = False) -> Any:
    """Return a fresh read-only descriptor (rclpy fills in each one's type)."""
    return rcl_interfaces.msg.ParameterDescriptor(
        read_only=True, description=description, dynamic_typing=dynamic
    )


class DriverNode(Node):
    """A node that publishes LaserScans with a fixed layout of ``bins`` over [0, 2*pi)."""

    def __init__(
        self, node_name: str, defaults: dict[str, Any], qos_depth: int, **kwargs: Any
    ) -> None:
        """Declare and check the common parameters, then create the publisher."""
        super().__init__(node_name, **kwargs)
        self._defaults = defaults
        port = self._declare('port', 'serial device of the LIDAR')
        baudrate = self._declare('baudrate', 'serial speed in baud')
        frame_id = self._declare('frame_id', 'LaserScan header frame')
        scan_topic = self._declare('scan_topic', 'LaserScan output topic')
        range_min = self._number('range_min', 'LaserScan range_min in metres')
        range_max = self._number('range_max', 'LaserScan range_max in metres')
        bins = self._declare('bins', 'bins over [0, 2*pi)')
        timeout = self._number('timeout', 'seconds without data before the driver gives up')
        invert = self._declare('invert', 'device angles are clockwise: negate them')
        offset = self._number(
            'angle_offset_deg',
            "added to the (negated) device angle: where the device's zero points, degrees "
            'counter-clockwise from forward (the FOSSBot v2: -90)',
        )
        bin_mode = self._declare('bin_mode', f'bin rule: {", ".join(BIN_MODES)}')
        if not port:
            raise ConfigError('port must name a serial device')
        if baudrate <= 0:
            raise ConfigError(f'baudrate must be positive, got {baudrate}')
        if bins <= 0:
            raise ConfigError(f'bins must be positive, got {bins}')
        if not 0.0 <= range_min < range_max:
            raise ConfigError(
                f'need 0 <= range_min < range_max, got range_min={range_min}, '
                f'range_max={range_max}'
            )
        if timeout <= 0.0:
            raise ConfigError(f'timeout must be positive, got {timeout}')
        if bin_mode not in BIN_MODES:
            raise ConfigError(f'bin_mode must be one of {list(BIN_MODES)}, got {bin_mode!r}')
        self.settings = DriverSettings(
            port=port,
            baudrate=baudrate,
            frame_id=frame_id,
            scan_topic=scan_topic,
            range_min=range_min,
            range_max=range_max,
            bins=bins,
            timeout=timeout,
            invert=invert,
            angle_offset_deg=offset,
            bin_mode=bin_mode,
        )
        self._increment = scan_increment(bins)
        self._angle_max = scan_angle_max(bins)
        self._publisher = self.create_publisher(LaserScan, scan_topic, QoSProfile(depth=qos_depth))
        self.scans_published = 0

    def _declare(self, name: str, description: str) -> Any:
        """Declare a read-only parameter with this driver's default; return its value."""
        return self.declare_parameter(name, self._defaults[name], _descriptor(description)).value

    def _number(self, name: str, description: str) -> float:
        """Declare a float parameter that also accepts an integer (``timeout:=2``)."""
        value = self.declare_parameter(
            name, float(self._defaults[name]), _descriptor(description, dynamic=True)
        ).value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f'{name} must be a number, got {value!r}')
        if not math.isfinite(value):
            raise ConfigError(f'{name} must be finite, got {value}')
        return float(value)

    def declare_extra(self, name: str, description: str) -> Any:
        """Declare a driver-specific read-only parameter from the defaults."""
        return self._declare(name, description)

    def publish_scan(self, ranges: np.ndarray, scan_time: float, samples: int) -> None:
        """Publish ``bins`` ranges (from ``samples`` readings) as one LaserScan, stamped now."""
        s = self.settings
        msg = LaserScan()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = s.frame_id
        msg.angle_min = 0.0
        msg.angle_max = self._angle_max
        msg.angle_increment = self._increment
        scan_time = max(float(scan_time), 0.0)
        msg.scan_time = scan_time
        msg.time_increment = scan_time / s.bins
        msg.range_min = s.range_min
        msg.range_max = s.range_max
        # array.array('f') is rclpy's fast path for a float32 sequence.
        msg.ranges = array.array('f', np.asarray(ranges, dtype=np.float32).tobytes())
        self._publisher.publish(msg)
        self.scans_published += 1
        if self.scans_published == 1:
            self.get_logger().info(
                f'first scan on {s.scan_topic}: {samples} samples in {scan_time:.3f} s'
            )


class _Spinner:
    """Spin a node in a background thread until told to stop."""

    def __init__(self, node: Node) -> None:
        """Prepare an executor for ``node``; nothing runs until ``start``."""
        self._executor = SingleThreadedExecutor()
        self._executor.add_node(node)
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._spin, name='ros-spin', daemon=True)
        self._logger = node.get_logger()

    def start(self) -> None:
        """Begin spinning."""
        self._thread.start()

    def _spin(self) -> None:
        try:
            while not self._done.is_set():
                self._executor.spin_once(timeout_sec=0.2)
        except ExternalShutdownException:
            pass
        except Exception as err:  # noqa: B902 - the thread must not die silently
            if not self._done.is_set():
                self._logger.error(f'executor thread stopped: {err}')

    def stop(self) -> None:
        """Stop spinning and wait (bounded) for the thread."""
        self._done.set()
        self._executor.wake()
        self._thread.join(timeout=2.0)
        self._executor.shutdown(timeout_sec=0.5)


def run(
    node_name: str,
    make_node: Callable[[], DriverNode],
    serve: Callable[[DriverNode, StopRequest], None],
    args: list[str] | None = None,
) -> int:
    """
    Run ``serve`` under rclpy until it returns, fails or a signal stops it.

    rclpy's own SIGINT/SIGTERM handlers are turned off: they would shut the
    context down under a driver that is still publishing (the race the
    reference node has to tolerate). Ours only note the stop and cancel the
    blocking serial read, so ``serve`` returns through its own clean-up
    (stop the scan and the motor, close the port). Before rclpy is up there
    is nothing to clean, so there they raise KeyboardInterrupt.
    """
    stop = StopRequest()
    initialised = False

    def on_signal(signum: int, frame: object) -> None:
        stop.request()
        if not initialised:
            raise KeyboardInterrupt

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    node = None
    spinner = None
    logger = rclpy.logging.get_logger(node_name)
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
        initialised = True
        node = make_node()
        logger = node.get_logger()
        spinner = _Spinner(node)
        spinner.start()
        serve(node, stop)
    except (
        ConfigError,
        InvalidParameterTypeException,
        InvalidTopicNameException,
        ParameterException,
    ) as err:
        logger.fatal(f'configuration error: {err}')
        return EXIT_CONFIG_ERROR
    except PortError as err:
        logger.fatal(str(err))
        return EXIT_CONFIG_ERROR
    except DeviceError as err:
        logger.error(str(err))
        return EXIT_DEVICE_ERROR
    except KeyboardInterrupt:
        pass
    finally:
        if spinner is not None:
            spinner.stop()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return EXIT_OK
