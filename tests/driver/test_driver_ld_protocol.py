"""LD06/LD19 packets: CRC8, decoding, point angles, the plausibility rule, resync."""

from __future__ import annotations

import random

import numpy as np
import pytest
from driver_wire import LD06_MANUAL_PACKET, ld_packet
from fossbot_lidar_driver.ld_protocol import (
    LdStreamParser,
    PacketError,
    crc8,
    decode_packet,
    packet_angles,
    span_plausible,
)
from ld_crc_reference import ld_crc8_bitwise

POINTS = [(1000 + i, 200) for i in range(12)]


def good(start: int = 0, end: int = 880, speed: int = 3600) -> bytes:
    return ld_packet(speed, start, end, POINTS)


def test_table_crc_equals_the_bitwise_reference() -> None:
    """The driver's table CRC agrees with the slow CRC-8/0x4D on random data."""
    rng = random.Random(7)
    for size in (0, 1, 2, 46, 100):
        data = bytes(rng.randrange(256) for _ in range(size))
        assert crc8(data) == ld_crc8_bitwise(data)
    assert [crc8(bytes([b])) for b in range(4)] == [0x00, 0x4D, 0x9A, 0xD7]


def test_the_manual_example_packet_decodes() -> None:
    """The LD06 manual's packet: its CRC (0x50) checks, and its fields come out."""
    packet = decode_packet(LD06_MANUAL_PACKET)
    assert (packet.speed_dps, packet.start_angle, packet.end_angle) == (2152, 32427, 33470)
    assert (packet.distances_mm[0], packet.intensities[0]) == (224, 228)
    assert (packet.distances_mm[-1], packet.intensities[-1]) == (192, 229)
    assert packet.timestamp_ms == 6714


def test_angles_use_the_sdks_whole_hundredth_step() -> None:
    """Span 10.43 degrees over 11 gaps: step 0.94 (integer division), last point 334.61."""
    angles = packet_angles(decode_packet(LD06_MANUAL_PACKET))
    assert angles[0] == pytest.approx(324.27)
    assert angles[-1] == pytest.approx(334.61)


def test_angles_wrap_inside_a_packet() -> None:
    """A packet across 0 degrees: angles stay in [0, 360)."""
    angles = packet_angles(decode_packet(good(start=35600, end=480)))
    assert angles[0] == pytest.approx(356.0)
    assert np.all((angles >= 0.0) & (angles < 360.0))
    assert angles[-1] == pytest.approx(4.8)


def test_plausibility_is_the_vendor_rule() -> None:
    """Span (whole degrees) <= 1.5 x what 12 points cover at the speed; speed 0 fails."""
    assert span_plausible(decode_packet(good(speed=3600)))
    assert not span_plausible(decode_packet(good(speed=0)))
    # The manual's own example: 10 degrees at 2152 deg/s (limit 8.6) fails the SDK's check.
    assert not span_plausible(decode_packet(LD06_MANUAL_PACKET))


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"\x54\x2c" + bytes(44), "47 bytes"),
        (b"\x55\x2c" + bytes(45), "bad header"),
        (LD06_MANUAL_PACKET[:-1] + b"\x51", "CRC mismatch"),
    ],
)
def test_decode_refuses_bad_packets(data: bytes, message: str) -> None:
    """Wrong size, header or CRC: a PacketError that says which."""
    with pytest.raises(PacketError, match=message):
        decode_packet(data)


def test_parser_reassembles_packets_fed_a_byte_at_a_time() -> None:
    """Packets split anywhere across reads still come out whole, in order."""
    stream = good(0, 880) + good(960, 1840)
    parser = LdStreamParser()
    packets = [p for i in range(len(stream)) for p in parser.feed(stream[i : i + 1])]
    assert [p.start_angle for p in packets] == [0, 960]
    assert (parser.crc_errors, parser.skipped_bytes) == (0, 0)


def test_parser_skips_noise_and_a_corrupt_packet() -> None:
    """Garbage, then a packet with a bad CRC, then good ones: only the good ones."""
    corrupt = bytearray(good(960, 1840))
    corrupt[10] ^= 0xFF
    stream = b"\x00\x13\x54" + bytes(corrupt) + good(1920, 2800) + good(2880, 3760)
    packets = LdStreamParser().feed(stream)
    assert [p.start_angle for p in packets] == [1920, 2880]


def test_parser_resyncs_inside_a_false_header_window() -> None:
    """A stray 54 2C whose 47 bytes overlap a real packet: the real packet is found."""
    real = good(960, 1840)
    stray = b"\x54\x2c\x01\x02"
    assert ld_crc8_bitwise((stray + real)[:46]) != (stray + real)[46]
    parser = LdStreamParser()
    packets = parser.feed(stray + real)
    assert [p.start_angle for p in packets] == [960]
    assert parser.crc_errors == 1 and parser.skipped_bytes == len(stray)


def test_parser_keeps_a_trailing_header_byte() -> None:
    """A read that ends on 0x54 keeps it: it may begin the next packet."""
    data = good(0, 880)
    parser = LdStreamParser()
    assert parser.feed(b"\x99" + data[:1]) == []
    assert [p.start_angle for p in parser.feed(data[1:])] == [0]
    assert parser.skipped_bytes == 1
