"""
The LDROBOT LD06/LD19 serial stream: packets, CRC8 and point angles (pure).

The device only talks: 230400 baud, 8N1, a 47-byte packet about every
2.7 ms (4500 points/s, 12 per packet)::

    0x54 0x2C | speed u16 (deg/s) | start angle u16 (0.01 deg)
    | 12 x (distance u16 mm, intensity u8) | end angle u16 (0.01 deg)
    | timestamp u16 (ms) | CRC8 of the 46 bytes before it

All numbers little-endian. The CRC is CRC-8 with polynomial 0x4D, initial
value 0, no reflection (its table starts 0x00 0x4d 0x9a 0xd7, as in the
vendor SDK). Angles of the 12 points are interpolated between start and
end as the vendor SDK (ldlidar_stl_ros2, lipkg.cpp) does it.
"""

from __future__ import annotations

from dataclasses import dataclass
import struct

import numpy as np

__all__ = [
    'HEADER',
    'PACKET_SIZE',
    'POINTS_PER_PACKET',
    'LdPacket',
    'LdStreamParser',
    'PacketError',
    'crc8',
    'decode_packet',
    'packet_angles',
    'span_plausible',
]

HEADER = b'\x54\x2c'
PACKET_SIZE = 47
POINTS_PER_PACKET = 12
POINTS_PER_SECOND = 4500  # LD06 and LD19
_POLY = 0x4D
_BODY = struct.Struct('<2xHH' + 'HB' * POINTS_PER_PACKET + 'HHB')


def _crc_table() -> tuple[int, ...]:
    """Return the MSB-first CRC-8 table for polynomial 0x4D."""
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = ((crc << 1) ^ _POLY) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
        table.append(crc)
    return tuple(table)


_TABLE = _crc_table()


def crc8(data: bytes) -> int:
    """Return the LD packet CRC of ``data``."""
    crc = 0
    for byte in data:
        crc = _TABLE[crc ^ byte]
    return crc


class PacketError(ValueError):
    """Bytes that are not a valid LD packet."""


@dataclass(frozen=True)
class LdPacket:
    """One decoded packet, in the device's units."""

    speed_dps: int  # rotation speed, degrees per second
    start_angle: int  # 0.01 degree, clockwise
    end_angle: int  # 0.01 degree, of the last point
    distances_mm: tuple[int, ...]
    intensities: tuple[int, ...]
    timestamp_ms: int


def decode_packet(data: bytes) -> LdPacket:
    """Decode exactly one 47-byte packet; raise PacketError on a bad header or CRC."""
    if len(data) != PACKET_SIZE:
        raise PacketError(f'an LD packet has {PACKET_SIZE} bytes, got {len(data)}')
    if data[:2] != HEADER:
        raise PacketError(f'bad header {data[:2].hex()}, expected {HEADER.hex()}')
    if crc8(data[:-1]) != data[-1]:
        raise PacketError(f'CRC mismatch: computed {crc8(data[:-1]):#04x}, sent {data[-1]:#04x}')
    fields = _BODY.unpack(data)
    points = fields[2:-3]
    return LdPacket(
        speed_dps=fields[0],
        start_angle=fields[1],
        end_angle=fields[-3],
        distances_mm=tuple(points[0::2]),
        intensities=tuple(points[1::2]),
        timestamp_ms=fields[-2],
    )


def packet_angles(packet: LdPacket) -> np.ndarray:
    """
    Return the 12 point angles in degrees, [0, 360), as the vendor SDK computes them.

    The step is the span over 11 gaps in whole 0.01 degree (the SDK divides
    integers), so it can be up to 0.01 degree short of the exact span / 11.
    """
    span = (packet.end_angle + 36000 - packet.start_angle) % 36000
    step = (span // (POINTS_PER_PACKET - 1)) / 100.0
    angles = packet.start_angle / 100.0 + np.arange(POINTS_PER_PACKET) * step
    return np.where(angles >= 360.0, angles - 360.0, angles)


def span_plausible(packet: LdPacket, points_per_second: int = POINTS_PER_SECOND) -> bool:
    """
    Return whether the packet's span fits its speed, the vendor SDK's sanity check.

    The SDK keeps a packet only if its span in whole degrees is at most 1.5
    times what 12 points cover at the reported speed; a stopped device
    (speed 0) therefore sends nothing usable.
    """
    span_deg = (packet.end_angle // 100 - packet.start_angle // 100 + 360) % 360
    return span_deg <= packet.speed_dps * POINTS_PER_PACKET / points_per_second * 1.5


class LdStreamParser:
    """
    Cut a byte stream into packets, resynchronising after noise or a bad CRC.

    After a bad CRC the search resumes one byte after that header (the
    vendor SDK skips the whole 47 bytes), so a packet that starts inside
    the damaged one is still found.
    """

    def __init__(self) -> None:
        """Start with nothing buffered."""
        self._buffer = bytearray()
        self.crc_errors = 0
        self.skipped_bytes = 0

    def feed(self, data: bytes) -> list[LdPacket]:
        """Add bytes; return the packets completed by them, in order."""
        self._buffer += data
        packets: list[LdPacket] = []
        while True:
            start = self._buffer.find(HEADER)
            if start < 0:
                # Keep a trailing 0x54: it may be the first byte of a header.
                keep = 1 if self._buffer[-1:] == HEADER[:1] else 0
                self.skipped_bytes += len(self._buffer) - keep
                del self._buffer[: len(self._buffer) - keep]
                return packets
            if start:
                self.skipped_bytes += start
                del self._buffer[:start]
            if len(self._buffer) < PACKET_SIZE:
                return packets
            candidate = bytes(self._buffer[:PACKET_SIZE])
            try:
                packets.append(decode_packet(candidate))
            except PacketError:
                self.crc_errors += 1
                self.skipped_bytes += 1
                del self._buffer[:1]
                continue
            del self._buffer[:PACKET_SIZE]
