"""The LD06/LD19 CRC-8 computed the slow obvious way, to check the table-driven ones."""

from __future__ import annotations


def ld_crc8_bitwise(data: bytes) -> int:
    """CRC-8, polynomial 0x4D, MSB first, init 0: one bit at a time, no table."""
    crc = 0
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x4D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc
