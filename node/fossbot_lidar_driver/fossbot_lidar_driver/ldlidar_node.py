"""
LDROBOT LD06/LD19 on a serial port to sensor_msgs/LaserScan.

The device streams 47-byte packets at 230400 baud and takes no requests.
Points are grouped into revolutions where their angle wraps, and each
revolution is published on a fixed layout of ``bins`` (450: 0.8 degree, what
an LD19 at 10 Hz measures) over [0, 2*pi). Readings follow the vendor ROS 2
driver (ldlidar_stl_ros2): no return (distance 0 and intensity 0) and empty
bins are NaN, every other reading is published as sent. Angles default to
the FOSSBot v2 bridge's mapping (``invert`` true, ``angle_offset_deg`` -90, a
device whose zero points to the robot's right); a device mounted zero
forward needs ``-p angle_offset_deg:=0.0``. Run it as ``ros2 run
fossbot_lidar_driver ldlidar_node --ros-args -p port:=/dev/ttyUSB0``.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import serial
from serial import SerialException

from .binning import ld_ranges
from .driver_node import DeviceError, DriverNode, PortError, run, StopRequest
from .ld_protocol import LdStreamParser, packet_angles, PACKET_SIZE, span_plausible
from .revolutions import LdRevolutionSplitter, Revolution

__all__ = ['DEFAULTS', 'NODE_NAME', 'main']

NODE_NAME = 'ldlidar_published'  # the vendor driver's node name
QOS_DEPTH = 10  # the vendor driver: reliable, keep-last 10
DEFAULTS: dict[str, Any] = {
    'port': '/dev/ttyUSB0',
    'baudrate': 230400,
    'frame_id': 'lidar_scan_frame',
    'scan_topic': '/scan',
    'range_min': 0.02,
    'range_max': 25.0,  # the vendor driver's header value (LD19 data sheet: 12 m)
    'bins': 450,
    'timeout': 1.0,
    # The FOSSBot v2 bridge's mapping: the A1's zero points to the robot's right.
    'invert': True,
    'angle_offset_deg': -90.0,
    'bin_mode': 'nearest',
}
# Upper bound of one blocking read: how late a stop or a silence is noticed.
READ_SLICE = 0.1


def _publish(node: DriverNode, revolution: Revolution) -> None:
    """Publish one revolution on the fixed layout."""
    s = node.settings
    ranges = ld_ranges(
        revolution.angles_deg,
        revolution.distances_mm,
        revolution.intensities,
        s.bins,
        invert=s.invert,
        angle_offset_deg=s.angle_offset_deg,
        mode=s.bin_mode,
    )
    node.publish_scan(ranges, revolution.duration, len(revolution))


def serve(node: DriverNode, stop: StopRequest) -> None:
    """Read packets and publish revolutions until stopped, or until the stream fails."""
    s = node.settings
    if stop.requested:
        return
    try:
        port = serial.Serial(s.port, s.baudrate, timeout=min(READ_SLICE, s.timeout))
    except (SerialException, OSError, ValueError) as err:
        raise PortError(f'cannot open {s.port}: {err}') from err
    logger = node.get_logger()
    logger.info(
        f'{s.port} at {s.baudrate} baud -> {s.scan_topic} ({s.bins} bins, frame {s.frame_id})'
    )
    parser = LdStreamParser()
    splitter = LdRevolutionSplitter()
    implausible = 0
    try:
        stop.add_canceller(port.cancel_read)
        last_packet = time.monotonic()
        while not stop.requested:
            data = port.read(max(PACKET_SIZE, port.in_waiting))
            now = time.monotonic()
            for packet in parser.feed(data):
                if not span_plausible(packet):
                    implausible += 1
                    continue
                last_packet = now
                for revolution in splitter.add_packet(
                    packet_angles(packet), packet.distances_mm, packet.intensities, now
                ):
                    _publish(node, revolution)
            if now - last_packet > s.timeout and not stop.requested:
                raise DeviceError(
                    f'LD LIDAR on {s.port}: no valid packet for {s.timeout} s '
                    f'({parser.crc_errors} CRC errors, {implausible} implausible packets, '
                    f'{parser.skipped_bytes} bytes skipped)'
                )
    except (SerialException, OSError) as err:
        if not stop.requested:
            raise DeviceError(f'LD LIDAR on {s.port}: {err}') from err
    finally:
        try:
            port.close()
        except (SerialException, OSError) as err:
            logger.debug(f'close: {err}')


def main(args: list[str] | None = None) -> int:
    """Run the LD06/LD19 driver; return the exit code (0 stopped, 1 device error, 2 config)."""
    return run(NODE_NAME, lambda: DriverNode(NODE_NAME, DEFAULTS, QOS_DEPTH), serve, args)


if __name__ == '__main__':
    sys.exit(main())
