"""Emulated LIDAR devices: pure protocol codecs, no serial I/O.

``revolution`` turns an emitted Scan into device samples (clockwise degrees,
millimetres); ``rplidar`` is the Slamtec RPLIDAR A1M8's request/response
state machine, ``rplidar_scans`` its scan encoders and reference decoders;
``ldlidar`` the LDROBOT LD06/LD19 packet stream. A serial front end paces
their bytes onto a pty or a real port.
"""

from harness.devices.ldlidar import LdlidarDevice, decode_packets
from harness.devices.revolution import Sample, samples_from_scan
from harness.devices.rplidar import RplidarDevice, encode_request
from harness.devices.rplidar_scans import decode_express, decode_standard

__all__ = [
    "LdlidarDevice",
    "RplidarDevice",
    "Sample",
    "decode_express",
    "decode_packets",
    "decode_standard",
    "encode_request",
    "samples_from_scan",
]
