"""The toy LIDAR's board driver: its lines on a serial port to sensor_msgs/LaserScan.

A line is a sample; a revolution ends where the angle wraps (as an LD06's
does), so it is published when the next begins. Each is published on ``bins`` bins over
[0, 2*pi) with the bundled drivers' mapping (``invert``,
``angle_offset_deg``); no return and empty bins are +inf. Run as
``python -m toy_lidar.driver --ros-args -p port:=/dev/pts/N``.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any

import numpy as np
import serial
from serial import SerialException

from harness.board_driver.binning import bin_indices, nearest_per_bin
from harness.board_driver.driver_node import DeviceError, DriverNode, PortError, StopRequest, run
from toy_lidar.codec import BAUD, SAMPLES_PER_REV, decode_line

NODE_NAME = "toy_lidar_driver"
DEFAULTS: dict[str, Any] = {
    "port": "/dev/ttyUSB0",
    "baudrate": BAUD,
    "frame_id": "lidar_scan_frame",
    "scan_topic": "/scan",
    "range_min": 0.05,
    "range_max": 8.0,
    "bins": SAMPLES_PER_REV,
    "timeout": 1.0,
    "invert": True,
    "angle_offset_deg": -90.0,
    "bin_mode": "nearest",
}
READ_SLICE = 0.1  # longest blocking read: how late a stop is noticed


def _publish(node: DriverNode, pairs: list[tuple[float, float]], duration: float) -> None:
    s = node.settings
    angles = np.array([a for a, _ in pairs], dtype=np.float64)
    metres = np.array([d for _, d in pairs], dtype=np.float64) / 1000.0
    metres[metres == 0.0] = math.inf
    index = bin_indices(
        angles, s.bins, invert=s.invert, angle_offset_deg=s.angle_offset_deg, mode=s.bin_mode
    )
    node.publish_scan(nearest_per_bin(index, metres, s.bins, math.inf), duration, len(pairs))


def serve(node: DriverNode, stop: StopRequest) -> None:
    """Read lines and publish each as a scan until stopped, or until the line falls silent."""
    s = node.settings
    try:
        port = serial.Serial(s.port, s.baudrate, timeout=min(READ_SLICE, s.timeout))
    except (SerialException, OSError, ValueError) as err:
        raise PortError(f"cannot open {s.port}: {err}") from err
    pending = b""
    sweep: list[tuple[float, float]] = []
    started = last = time.monotonic()
    try:
        stop.add_canceller(port.cancel_read)
        while not stop.requested:
            pending += port.read(max(1, port.in_waiting))
            now = time.monotonic()
            *lines, pending = pending.split(b"\n")
            for line in lines:
                try:
                    pair = decode_line(line)
                except ValueError:
                    continue  # a line cut by the start of the stream
                last = now
                if sweep and pair[0] <= sweep[-1][0]:  # the angle wrapped: a new sweep
                    _publish(node, sweep, now - started)
                    sweep, started = [], now
                sweep.append(pair)
            if now - last > s.timeout and not stop.requested:
                raise DeviceError(f"toy LIDAR on {s.port}: no bytes for {s.timeout} s")
    except (SerialException, OSError) as err:
        if not stop.requested:
            raise DeviceError(f"toy LIDAR on {s.port}: {err}") from err
    finally:
        port.close()


def main(args: list[str] | None = None) -> int:
    """Run the driver; return its exit code (0 stopped, 1 device error, 2 config)."""
    return run(NODE_NAME, lambda: DriverNode(NODE_NAME, DEFAULTS, 10), serve, args)


if __name__ == "__main__":
    sys.exit(main())
