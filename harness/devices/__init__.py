"""Emulated LIDAR devices: pure protocol codecs, no serial I/O.

``revolution`` turns a Scan into device samples; ``rplidar``, ``rplidar_scans``
and ``ldlidar`` are the codecs; ``serial_line`` paces their bytes onto a port.
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
