"""The LD packet decoder on the LD06 manual's example packet (numpy only, no ROS)."""

from fossbot_lidar_driver.ld_protocol import crc8, decode_packet, LdStreamParser, packet_angles
import pytest

# LD06 development manual: speed 2152 deg/s, 324.27 -> 334.70 degrees, CRC 0x50.
MANUAL_PACKET = bytes.fromhex(
    '542c6808ab7e e000e4 dc00e2 d900e5 d500e3 d300e4 d000e9'
    'cd00e4 ca00e2 c700e9 c500e5 c200e5 c000e5 be82 3a1a 50'
)


def test_crc_table_starts_as_the_vendor_sdk():
    """CRC-8 with polynomial 0x4D: table 0x00 0x4d 0x9a 0xd7 ..."""
    assert [crc8(bytes([b])) for b in range(4)] == [0x00, 0x4D, 0x9A, 0xD7]
    assert crc8(MANUAL_PACKET[:46]) == 0x50


def test_manual_packet_fields_and_angles():
    """The example decodes; its angles step by 0.94 degree from 324.27."""
    packet = decode_packet(MANUAL_PACKET)
    assert (packet.speed_dps, packet.start_angle, packet.end_angle) == (2152, 32427, 33470)
    assert packet.distances_mm[:2] == (224, 220)
    assert packet_angles(packet)[1] == pytest.approx(325.21)


def test_parser_finds_the_packet_after_noise():
    """Leading noise is skipped; the packet comes out whole."""
    parser = LdStreamParser()
    assert len(parser.feed(b'\x00\x54\x00' + MANUAL_PACKET)) == 1
    assert parser.skipped_bytes == 3
