"""LD06/LD19 emulation: CRC, packet layout, revolutions, timestamps, resync."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from ld_crc_reference import ld_crc8_bitwise

from harness.devices import ldlidar as ld
from harness.devices.revolution import Sample, samples_from_scan
from harness.lidar.scan import Scan

# The example packet of the LD19 development manual (CRC 0x50).
MANUAL_PACKET = bytes.fromhex(
    "54 2c 68 08 ab 7e e0 00 e4 dc 00 e2 d9 00 e5 d5 00 e3 d3 00 e4 d0 00 e9"
    " cd 00 e4 ca 00 e2 c7 00 e9 c5 00 e5 c2 00 e5 c0 00 e5 be 82 3a 1a 50"
)


def uniform(n: int, *, offset: float = 0.0) -> list[Sample]:
    return [Sample((offset + k * 360.0 / n) % 360.0, 100.0 + 3 * k, 200) for k in range(n)]


def test_crc_table_starts_as_documented_and_matches_the_polynomial() -> None:
    assert ld.CRC_TABLE[:4] == (0x00, 0x4D, 0x9A, 0xD7)
    assert len(ld.CRC_TABLE) == 256
    assert all(ld.CRC_TABLE[i] == ld_crc8_bitwise(bytes([i])) for i in range(256))


def test_manual_packet_crc_and_fields() -> None:
    assert ld.crc8(MANUAL_PACKET[:-1]) == 0x50 == ld_crc8_bitwise(MANUAL_PACKET[:-1])
    packet = ld.parse_packet(MANUAL_PACKET)
    assert packet.speed_deg_s == 2152
    assert (packet.start_angle_cdeg, packet.end_angle_cdeg) == (32427, 33470)
    assert packet.timestamp_ms == 6714
    assert packet.points[0] == (224, 228) and packet.points[-1] == (192, 229)
    samples = packet.samples()
    assert samples[0].angle_deg == pytest.approx(324.27)
    assert samples[-1].angle_deg == pytest.approx(334.70)


def test_encoded_packet_golden_bytes() -> None:
    samples = [Sample(10.0 + 0.8 * k, 1000.0 + k, 200) for k in range(12)]
    body = bytes([0x54, 0x2C]) + (3600).to_bytes(2, "little") + (1000).to_bytes(2, "little")
    for k in range(12):
        body += (1000 + k).to_bytes(2, "little") + bytes([200])
    body += (1880).to_bytes(2, "little") + (1234).to_bytes(2, "little")
    expected = body + bytes([ld_crc8_bitwise(body)])
    assert ld.encode_packet(samples, speed_deg_s=3600, timestamp_ms=1234) == expected
    assert len(expected) == ld.PACKET_LEN == 47


def test_no_return_has_zero_intensity_and_timestamps_wrap() -> None:
    samples = [Sample(0.8 * k, 0.0 if k % 2 else 500.0, 180) for k in range(12)]
    packet = ld.parse_packet(ld.encode_packet(samples, speed_deg_s=3600, timestamp_ms=30_005))
    assert packet.timestamp_ms == 5
    assert [p for p in packet.points[1::2]] == [(0, 0)] * 6
    assert [p for p in packet.points[::2]] == [(500, 180)] * 6


def test_parse_packet_rejects_damage() -> None:
    with pytest.raises(ValueError):
        ld.parse_packet(MANUAL_PACKET[:-1])
    with pytest.raises(ValueError):
        ld.parse_packet(MANUAL_PACKET[:-1] + b"\x51")
    with pytest.raises(ValueError):
        ld.parse_packet(b"\x55" + MANUAL_PACKET[1:])


def test_a_revolution_round_trips() -> None:
    dev = ld.LdlidarDevice()
    assert dev.samples_per_revolution == 450  # 4500 samples/s at 3600 deg/s (10 Hz)
    assert dev.samples_per_packet == 12 and dev.rate_hz == 10.0
    samples = uniform(450, offset=0.4)
    data = dev.encode_revolution(samples, start_ms=0.0) + dev.encode_revolution(
        samples, start_ms=100.0
    )
    assert len(data) % 47 == 0 and len(data) // 47 == 75  # 900 samples, 12 per packet
    decoded, bad = ld.decode_packets(data)
    assert bad == 0
    for want, got in zip(samples * 2, decoded, strict=True):
        assert abs((want.angle_deg - got.angle_deg + 180) % 360 - 180) <= 0.005 + 1e-9
        assert got.distance_mm == round(want.distance_mm)
        assert got.quality == want.quality


def test_timestamps_advance_with_the_sample_rate() -> None:
    dev = ld.LdlidarDevice()
    data = dev.encode_revolution(uniform(450), start_ms=29_990.0)
    stamps = [ld.parse_packet(data[i : i + 47]).timestamp_ms for i in range(0, len(data), 47)]
    # 12 samples at 4500/s = 2.667 ms per packet; the counter wraps at 30000.
    expected = [int(29_990.0 + 12 * i * 1000 / 4500) % 30000 for i in range(len(stamps))]
    assert stamps == expected
    assert stamps[:6] == [29990, 29992, 29995, 29998, 0, 3]


def test_packets_pass_the_vendor_drivers_span_check() -> None:
    # ldlidar_stl_ros2 drops a packet whose (end - start) in whole degrees
    # exceeds speed * 12 / 4500 * 1.5.
    dev = ld.LdlidarDevice()
    data = dev.encode_revolution(uniform(450, offset=355.0), start_ms=0.0)
    for i in range(0, len(data), 47):
        p = ld.parse_packet(data[i : i + 47])
        diff = (p.end_angle_cdeg // 100 - p.start_angle_cdeg // 100 + 360) % 360
        assert diff <= p.speed_deg_s * 12 / 4500 * 1.5
        assert p.speed_deg_s == 3600


def test_decode_resyncs_after_garbage_and_skips_a_corrupted_packet() -> None:
    dev = ld.LdlidarDevice()
    data = bytearray(dev.encode_revolution(uniform(36), start_ms=0.0))  # 3 packets
    corrupted = bytearray(data)
    corrupted[47 + 10] ^= 0xFF  # a distance byte of the second packet
    stream = b"\x54\x2c\x00" + b"noise\x54" + bytes(corrupted) + b"\x54\x2c\x01\x02"
    samples, bad = ld.decode_packets(stream)
    assert bad == 2  # the fake header at the front, and the damaged packet
    assert samples == ld.decode_packets(bytes(data[:47]) + bytes(data[94:]))[0]
    assert len(samples) == 24


def test_a_return_left_of_the_robot_is_at_device_270() -> None:
    ranges = np.full(360, np.inf, dtype=np.float32)
    ranges[90] = 1.5  # CCW +90 degrees
    scan = Scan(0.0, 2 * math.pi - math.pi / 180, math.pi / 180, 0.0, 0.1, 0.02, 12.0, ranges)
    dev = ld.LdlidarDevice()
    samples = samples_from_scan(scan, samples_per_rev=dev.samples_per_revolution, quality=200)
    decoded, _ = ld.decode_packets(dev.encode_revolution(samples, start_ms=0.0))
    hits = [s for s in decoded if s.distance_mm]
    assert {round(s.angle_deg) for s in hits} == {270} and all(s.distance_mm == 1500 for s in hits)


def test_device_rejects_nonsense_rates() -> None:
    with pytest.raises(ValueError):
        ld.LdlidarDevice(speed_deg_s=0)
    with pytest.raises(ValueError):
        ld.encode_packet(uniform(11), speed_deg_s=3600, timestamp_ms=0)
    assert struct.calcsize("<BBHH") + 12 * 3 + 5 == ld.PACKET_LEN


def command_frame(cmd: int, payload: bytes = bytes(4)) -> bytes:
    """An LDROBOT command frame as LD14P drivers (lds2d 0.7.0, kaiaai/LDS) send it."""
    body = bytes((ld.HEADER, cmd, len(payload))) + payload
    return body + bytes((ld.crc8(body),))


def test_ld14p_command_frames_are_requests_it_ignores_not_errors() -> None:
    """lds2d's LD06/LD19 driver sends start/stop frames: logged as ignored requests."""
    assert command_frame(0xA0) == bytes.fromhex("54 A0 04 00 00 00 00 5E")  # what lds2d sends
    device = ld.LdlidarDevice()
    events = []
    device.listener = events.append
    start = command_frame(0xA0)
    assert device.receive(start[:3]) == b"" and not events  # a frame in pieces waits
    assert device.receive(start[3:] + command_frame(0xA1)) == b""
    assert [(e.kind, e.command) for e in events] == [
        ("request", "LD_START"),
        ("request", "LD_STOP"),
    ]
    assert "takes no commands and streams on" in events[0].text()
    assert device.counters == {"requests": 2, "ignored_host_bytes": 0}
    assert device.requests_by_command == {"LD_START": 1, "LD_STOP": 1}


def test_other_host_bytes_are_counted_and_an_rplidar_request_is_named() -> None:
    device = ld.LdlidarDevice()
    events = []
    device.listener = events.append
    bad_crc = bytearray(command_frame(0xA2, b"\x10\x0e\x00\x00"))
    bad_crc[-1] ^= 0xFF
    device.receive(bytes.fromhex("A5 50") + bytes(bad_crc) + b"\x54\x2c")
    device.drop_partial_request()  # the line went quiet inside "54 2C"
    assert [e.data for e in events] == [b"\xa5\x50", bytes(bad_crc), b"\x54\x2c"]
    assert all(e.kind == "ignored_host_bytes" for e in events)
    assert "RPLIDAR driver" in events[0].text()
    assert device.counters == {"requests": 0, "ignored_host_bytes": 2 + 8 + 2}
