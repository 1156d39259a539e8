"""LDROBOT LD06 / LD19: the packet stream the device sends, as pure code.

It takes no commands: it streams 47-byte packets of 12 measurements at
230400 baud; ``decode_packets`` is the slow, obvious reference the tests
check the encoder against. Facts and sources: docs/devices.md.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass

from harness.devices.events import DeviceEvent, Listener
from harness.devices.protocol import DeviceDefaults
from harness.devices.revolution import Sample

HEADER = 0x54
VER_LEN = 0x2C  # top 3 bits reserved, low 5 bits: points per packet (12)
POINTS_PER_PACKET = 12
PACKET_LEN = 47
BAUD = 230400
# LDROBOT command frames: 0x54, a command, 0x04, a 4-byte payload, CRC-8 of
# the first 7 bytes. Drivers written for the LD14P (lds2d 0.7.0, kaiaai/LDS)
# send start/stop/speed frames to an LD06/LD19 too, which streams anyway.
COMMAND_LEN = 8
COMMAND_PAYLOAD_LEN = 4
COMMAND_NAMES: dict[int, str] = {0xA0: "LD_START", 0xA1: "LD_STOP", 0xA2: "LD_SET_SPEED"}
TIMESTAMP_WRAP_MS = 30000
CRC_POLY = 0x4D
MAX_DISTANCE_MM = 0xFFFF
SAMPLES_PER_S = 4500
SPEED_DEG_S = 3600.0  # 10 Hz
# A return's intensity. Weak returns are removed by the vendor driver's near
# filter (mean intensity <= 15 in a group, < 220 for groups of 1-2 points).
DEFAULT_INTENSITY = 200

_HEAD = struct.Struct("<BBHH")  # header, ver_len, speed, start angle
_POINT = struct.Struct("<HB")  # distance mm, intensity
_TAIL = struct.Struct("<HH")  # end angle, timestamp


def _crc_table(poly: int) -> tuple[int, ...]:
    """The 256-entry lookup table of an MSB-first CRC-8 with this polynomial."""
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = ((crc << 1) ^ poly if crc & 0x80 else crc << 1) & 0xFF
        table.append(crc)
    return tuple(table)


CRC_TABLE: tuple[int, ...] = _crc_table(CRC_POLY)


def crc8(data: bytes) -> int:
    """The packet CRC (init 0, no reflection, no final xor), over the first 46 bytes."""
    crc = 0
    for byte in data:
        crc = CRC_TABLE[crc ^ byte]
    return crc


@dataclass(frozen=True)
class LdPacket:
    """One decoded packet, fields as on the wire."""

    speed_deg_s: int
    start_angle_cdeg: int  # 0.01 degree, clockwise
    end_angle_cdeg: int
    timestamp_ms: int  # wraps at 30000
    points: tuple[tuple[int, int], ...]  # (distance mm, intensity)

    def samples(self) -> list[Sample]:
        """The points with angles interpolated from start to end, as hosts do."""
        span = (self.end_angle_cdeg - self.start_angle_cdeg) % 36000
        step = span / (len(self.points) - 1)
        return [
            Sample(((self.start_angle_cdeg + i * step) / 100.0) % 360.0, float(dist), intensity)
            for i, (dist, intensity) in enumerate(self.points)
        ]


def _angle_cdeg(angle_deg: float) -> int:
    return int(round((angle_deg % 360.0) * 100)) % 36000


def encode_packet(samples: Sequence[Sample], *, speed_deg_s: float, timestamp_ms: int) -> bytes:
    """One 47-byte packet of 12 samples; hosts interpolate the angles in between."""
    if len(samples) != POINTS_PER_PACKET:
        raise ValueError(f"a packet holds {POINTS_PER_PACKET} samples, got {len(samples)}")
    body = bytearray(
        _HEAD.pack(HEADER, VER_LEN, int(round(speed_deg_s)), _angle_cdeg(samples[0].angle_deg))
    )
    for sample in samples:
        dist = min(max(int(round(sample.distance_mm)), 0), MAX_DISTANCE_MM)
        intensity = min(max(int(sample.quality), 0), 255) if dist else 0
        body += _POINT.pack(dist, intensity)
    body += _TAIL.pack(_angle_cdeg(samples[-1].angle_deg), timestamp_ms % TIMESTAMP_WRAP_MS)
    return bytes(body) + bytes((crc8(body),))


def parse_packet(packet: bytes) -> LdPacket:
    """Decode one packet; ValueError for a wrong length, header or CRC."""
    if len(packet) != PACKET_LEN:
        raise ValueError(f"a packet is {PACKET_LEN} bytes, got {len(packet)}")
    header, ver_len, speed, start = _HEAD.unpack_from(packet)
    if header != HEADER or ver_len != VER_LEN:
        raise ValueError(f"bad packet header {packet[:2].hex(' ')}")
    if crc8(packet[:-1]) != packet[-1]:
        raise ValueError("packet CRC mismatch")
    points = tuple(
        _POINT.unpack_from(packet, _HEAD.size + i * _POINT.size) for i in range(POINTS_PER_PACKET)
    )
    end, timestamp = _TAIL.unpack_from(packet, _HEAD.size + POINTS_PER_PACKET * _POINT.size)
    return LdPacket(speed, start, end, timestamp, points)


def decode_packets(data: bytes) -> tuple[list[Sample], int]:
    """Reference decoder: every good packet's samples, and how many failed the CRC.

    After a bad CRC it resumes one byte later, so garbage costs only itself; a
    trailing incomplete packet is ignored.
    """
    samples: list[Sample] = []
    bad = 0
    pos = 0
    while (pos := data.find(bytes((HEADER, VER_LEN)), pos)) >= 0:
        packet = data[pos : pos + PACKET_LEN]
        if len(packet) < PACKET_LEN:
            break
        if crc8(packet[:-1]) != packet[-1]:
            bad += 1
            pos += 1
            continue
        samples.extend(parse_packet(packet).samples())
        pos += PACKET_LEN
    return samples, bad


def starts_like_command(data: bytes | bytearray) -> bool:
    """Do these bytes begin as an LDROBOT command frame does (0x54, a command, length 4)?"""
    return len(data) >= 3 and data[0] == HEADER and data[2] == COMMAND_PAYLOAD_LEN


def _is_command_frame(frame: bytes) -> bool:
    """A whole LDROBOT command frame: its start, a 4-byte payload and its CRC-8."""
    return (
        len(frame) == COMMAND_LEN and starts_like_command(frame) and crc8(frame[:-1]) == frame[-1]
    )


class LdlidarDevice(DeviceDefaults):
    """An LD06/LD19 streaming at a fixed rotation speed and sample rate.

    No motor line, no reboot, no request it answers (``DeviceDefaults``);
    its encoder holds a partial packet between revolutions (``packetized``).
    """

    mode = "streaming"  # from power-up, unasked
    packetized = True

    def __init__(self, *, speed_deg_s: float = SPEED_DEG_S, samples_per_s: int = SAMPLES_PER_S):
        if speed_deg_s <= 0 or samples_per_s <= 0:
            raise ValueError("speed_deg_s and samples_per_s must be positive")
        self.speed_deg_s, self.samples_per_s = speed_deg_s, samples_per_s
        self._pending: list[tuple[Sample, float]] = []  # samples and their times (ms)
        # "requests": whole LDROBOT command frames (ignored, but not an error).
        self.counters: dict[str, int] = {"requests": 0, "ignored_host_bytes": 0}
        self.requests_by_command: dict[str, int] = {}
        self.listener: Listener | None = None  # told of host bytes, which it ignores
        self._rx = bytearray()

    @property
    def samples_per_revolution(self) -> int:
        """Native samples in one turn: 450 at 10 Hz and 4500 samples/s."""
        return max(1, round(self.samples_per_s * 360.0 / self.speed_deg_s))

    @property
    def samples_per_packet(self) -> int:
        return POINTS_PER_PACKET

    def set_rate(self, rate_hz: float) -> None:
        """Turn at `rate_hz`: every packet reports the speed."""
        self.speed_deg_s = 360.0 * rate_hz

    @property
    def rate_hz(self) -> float:
        return self.speed_deg_s / 360.0

    def encode_revolution(self, samples: Sequence[Sample], *, start_ms: float = 0.0) -> bytes:
        """Whole packets for one revolution whose first sample was taken at ``start_ms``.

        A packet carries its first sample's (wrapped) time; samples short of a
        packet wait for the next call, as the real stream runs across revolutions.
        """
        period_ms = 1000.0 / self.samples_per_s
        self._pending.extend((s, start_ms + k * period_ms) for k, s in enumerate(samples))
        out = bytearray()
        while len(self._pending) >= POINTS_PER_PACKET:
            chunk = self._pending[:POINTS_PER_PACKET]
            del self._pending[:POINTS_PER_PACKET]
            samples, stamp = [s for s, _ in chunk], int(chunk[0][1])
            out += encode_packet(samples, speed_deg_s=self.speed_deg_s, timestamp_ms=stamp)
        return bytes(out)

    def receive(self, data: bytes) -> bytes:
        """Host bytes: an LD06/LD19 answers none.

        LDROBOT command frames (an LD14P driver's) are logged as ignored requests;
        other bytes are counted (``ignored_host_bytes``): 0xA5 says an RPLIDAR
        driver is pointed at the wrong device.
        """
        rx = self._rx
        rx += data
        while rx:
            if rx[0] == HEADER:
                if len(rx) < COMMAND_LEN:
                    break  # perhaps a frame in pieces (drop_partial_request ends the wait)
                frame = bytes(rx[:COMMAND_LEN])
                if _is_command_frame(frame):
                    del rx[:COMMAND_LEN]
                    self._command(frame)
                    continue
            end = rx.find(HEADER, 1)
            end = len(rx) if end < 0 else end
            self._ignored(bytes(rx[:end]))
            del rx[:end]
        return b""

    def drop_partial_request(self) -> None:
        """The line went quiet inside what looked like a command frame: ignore its bytes."""
        if self._rx:
            self._ignored(bytes(self._rx))
            self._rx.clear()

    def _command(self, frame: bytes) -> None:
        name = COMMAND_NAMES.get(frame[1], f"LD_0x{frame[1]:02X}")
        self.counters["requests"] += 1
        self.requests_by_command[name] = self.requests_by_command.get(name, 0) + 1
        if self.listener is not None:
            note = "ignored: an LD06/LD19 takes no commands and streams on (an LD14P-style frame)"
            self.listener(DeviceEvent("request", frame, name, b"", note))

    def _ignored(self, data: bytes) -> None:
        self.counters["ignored_host_bytes"] += len(data)
        if self.listener is not None:
            note = (
                "an RPLIDAR request: this is an RPLIDAR driver; an LD06/LD19 takes no commands"
                if data[:1] == b"\xa5"
                else ""
            )
            self.listener(DeviceEvent("ignored_host_bytes", data, note=note))
