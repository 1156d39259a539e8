"""The emulator's bytes as the FOSSBot's own client reads them.

The robot reads its A1M8 with the PyPI ``rplidar`` package (SkoltechRobotics).
Here only its pure decoding runs: ``_process_scan`` on each standard node,
and its descriptor and GET_INFO parsing rules; the over-a-pty client tests
live with the serial front end.
"""

from __future__ import annotations

import codecs

import rplidar

from harness.devices import rplidar as rp
from harness.devices.revolution import Sample


def test_rplidar_package_decodes_every_standard_node() -> None:
    dev = rp.RplidarDevice()
    dev.set_motor(True)
    assert dev.receive(rp.encode_request(rp.CMD_SCAN))
    samples = [Sample(k * 360 / 358, 150.0 + 31.7 * k, k % 64) for k in range(358)]
    data = dev.encode_revolution(samples) + dev.encode_revolution(samples)
    measures = [rplidar._process_scan(data[i : i + 5]) for i in range(0, len(data), 5)]
    assert [m[0] for m in measures].count(True) == 2  # one new_scan per revolution
    assert measures[0][0] and measures[358][0]
    for (_new_scan, quality, angle, distance), want in zip(measures, samples * 2, strict=True):
        assert abs(angle - want.angle_deg) <= 1 / 128
        assert abs(distance - want.distance_mm) <= 1 / 8
        assert quality == want.quality


def test_rplidar_package_descriptor_and_info_rules() -> None:
    dev = rp.RplidarDevice()
    scan = dev.receive(rp.encode_request(rp.CMD_SCAN))
    # RPLidar._read_descriptor: size = byte 2, single iff byte 5 == 0, type = last byte.
    assert (scan[2], scan[-2] == 0, scan[-1]) == (5, False, rplidar.SCAN_TYPE)
    info = rp.RplidarDevice().receive(rp.encode_request(rp.CMD_GET_INFO))
    head, raw = info[:7], info[7:]
    assert (head[2], head[-2] == 0, head[-1]) == (rplidar.INFO_LEN, True, rplidar.INFO_TYPE)
    # RPLidar.get_info's own field layout.
    assert (raw[0], (raw[2], raw[1]), raw[3]) == (0x18, (1, 29), 7)
    serial = codecs.decode(codecs.encode(raw[4:], "hex").upper(), "ascii")
    assert serial == rp.DEFAULT_SERIAL.hex().upper()
    health = rp.RplidarDevice().receive(rp.encode_request(rp.CMD_GET_HEALTH))
    assert (health[2], health[-4], health[-3]) == (rplidar.HEALTH_LEN, rplidar.HEALTH_TYPE, 0)
