"""Hand-made device bytes for the driver tests: Slamtec replies and LD packets.

Written from the protocol descriptions, not with the driver's own code, so
the driver's decoding is checked against an independent encoder. The LD CRC
here is the slow bit-by-bit form of CRC-8/0x4D; the driver's is table-driven.
"""

from __future__ import annotations

import os
import select
import struct
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from ld_crc_reference import ld_crc8_bitwise

# Slamtec descriptors: A5 5A, then u32 LE = length (30 bits) | mode << 30, then the type.
INFO_DESCRIPTOR = bytes.fromhex("a55a1400000004")
HEALTH_DESCRIPTOR = bytes.fromhex("a55a0300000006")
SCAN_DESCRIPTOR = bytes.fromhex("a55a0500004081")
# GET_INFO body: model, firmware minor, firmware major, hardware, 16-byte serial number.
INFO_BODY = bytes([0x18, 0x1D, 0x01, 0x07]) + bytes(range(0xA0, 0xB0))

CMD_STOP, CMD_RESET, CMD_SCAN = 0x25, 0x40, 0x20
CMD_GET_INFO, CMD_GET_HEALTH, CMD_MOTOR_PWM = 0x50, 0x52, 0xF0


def rp_sample(start: bool, quality: int, angle_deg: float, distance_mm: float) -> bytes:
    """One 5-byte standard-scan sample: S/!S flags, quality, angle (q6), distance (q2)."""
    byte0 = (quality << 2) | ((0 if start else 1) << 1) | (1 if start else 0)
    angle_q6 = round(angle_deg * 64)
    return struct.pack("<BHH", byte0, (angle_q6 << 1) | 1, round(distance_mm * 4))


def rp_revolution(samples: Sequence[tuple[int, float, float]]) -> bytes:
    """A revolution: the first sample carries the start flag. Items: (quality, angle, mm)."""
    return b"".join(
        rp_sample(i == 0, quality, angle, distance)
        for i, (quality, angle, distance) in enumerate(samples)
    )


def ld_packet(
    speed_dps: int,
    start_cdeg: int,
    end_cdeg: int,
    points: Sequence[tuple[int, int]],
    timestamp_ms: int = 0,
    *,
    crc: int | None = None,
) -> bytes:
    """One 47-byte LD06/LD19 packet; ``points`` are 12 (distance mm, intensity)."""
    assert len(points) == 12
    body = struct.pack("<BBHH", 0x54, 0x2C, speed_dps, start_cdeg)
    body += b"".join(struct.pack("<HB", d, i) for d, i in points)
    body += struct.pack("<HH", end_cdeg, timestamp_ms)
    return body + bytes([ld_crc8_bitwise(body) if crc is None else crc])


# From the LD06 development manual: speed 2152 deg/s, 324.27 -> 334.70 deg, CRC 0x50.
LD06_MANUAL_PACKET = bytes.fromhex(
    "542c6808ab7ee000e4dc00e2d900e5d500e3d300e4d000e9cd00e4ca00e2c700e9c500e5c200e5c000e5be823a1a50"
)


@dataclass
class Pty:
    """A pseudo-terminal: the driver opens ``name``; the test plays the device on ``master``.

    Threads using the master poll it (select, 50 ms) instead of blocking in a
    read or write: a thread blocked in a syscall keeps the file open, and
    the driver would never see the hang-up that ``close`` is meant to cause.
    """

    master: int
    slave: int
    name: str
    closed: bool = False
    threads: list[threading.Thread] = field(default_factory=list)

    @classmethod
    def open(cls) -> Pty:
        master, slave = os.openpty()
        return cls(master, slave, os.ttyname(slave))

    def run(self, target: Callable[[], None]) -> None:
        """Run ``target`` in a daemon thread that ``close`` waits for."""
        thread = threading.Thread(target=target, daemon=True)
        self.threads.append(thread)
        thread.start()

    def read(self, size: int = 256) -> bytes | None:
        """Bytes the driver sent (maybe none yet), or None once closed."""
        while not self.closed:
            readable, _, _ = select.select([self.master], [], [], 0.05)
            if readable:
                try:
                    return os.read(self.master, size)
                except OSError:
                    return None
        return None

    def write(self, data: bytes) -> bool:
        """Write everything, or return False once the pty is closed."""
        view = memoryview(data)
        while view and not self.closed:
            _, writable, _ = select.select([], [self.master], [], 0.05)
            if writable:
                try:
                    view = view[os.write(self.master, view) :]
                except OSError:
                    return False
        return not self.closed

    def close(self) -> None:
        """Hang up both ends: the driver's next read fails as if the device were unplugged."""
        if self.closed:
            return
        self.closed = True
        for thread in self.threads:
            thread.join(timeout=1.0)
        os.close(self.master)
        os.close(self.slave)


@dataclass
class RplidarResponder:
    """A scripted RPLIDAR: answers GET_INFO, GET_HEALTH, SCAN; streams until STOP.

    Not an emulator: it replays ``revolution`` (bytes) every ``period`` seconds,
    after ``lead_in`` once, and records every request it parses.
    """

    pty: Pty
    revolution: bytes
    period: float = 0.05
    lead_in: bytes = b""
    health: int = 0  # 0 Good, 1 Warning, 2 Error
    send_samples: bool = True
    corrupt_revolution: int | None = None  # damage this revolution (0 = the first) once
    requests: list[tuple[int, bytes]] = field(default_factory=list)
    _scanning: threading.Event = field(default_factory=threading.Event)
    _done: threading.Event = field(default_factory=threading.Event)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def start(self) -> RplidarResponder:
        self.pty.run(self._serve_requests)
        self.pty.run(self._stream)
        return self

    def stop(self) -> None:
        self._done.set()

    def commands(self) -> list[int]:
        with self._lock:
            return [cmd for cmd, _ in self.requests]

    def _serve_requests(self) -> None:
        buffer = bytearray()
        while not self._done.is_set():
            chunk = self.pty.read()
            if chunk is None:
                return
            buffer += chunk
            while True:
                request = self._take_request(buffer)
                if request is None:
                    break
                with self._lock:
                    self.requests.append(request)
                self._answer(*request)

    @staticmethod
    def _take_request(buffer: bytearray) -> tuple[int, bytes] | None:
        """Cut one request off the buffer: A5 cmd [size payload checksum]."""
        start = buffer.find(0xA5)
        if start < 0:
            buffer.clear()
            return None
        del buffer[:start]
        if len(buffer) < 2:
            return None
        cmd = buffer[1]
        if not cmd & 0x80:  # no payload
            del buffer[:2]
            return cmd, b""
        if len(buffer) < 3 or len(buffer) < 4 + buffer[2]:
            return None
        size = buffer[2]
        payload = bytes(buffer[3 : 3 + size])
        del buffer[: 4 + size]
        return cmd, payload

    def _answer(self, cmd: int, payload: bytes) -> None:
        if cmd == CMD_GET_INFO:
            self.pty.write(INFO_DESCRIPTOR + INFO_BODY)
        elif cmd == CMD_GET_HEALTH:
            self.pty.write(HEALTH_DESCRIPTOR + bytes([self.health, 0, 0]))
        elif cmd == CMD_SCAN:
            self.pty.write(SCAN_DESCRIPTOR)
            self._scanning.set()
        elif cmd == CMD_STOP:
            self._scanning.clear()

    def _stream(self) -> None:
        """Stream while scanning (SCAN starts it again after a STOP)."""
        sent = 0
        while not self._done.is_set() and not self.pty.closed:
            if not self._scanning.wait(timeout=0.05) or not self.send_samples:
                continue
            data = self.revolution
            if sent == 0:
                data = self.lead_in + data
            if sent == self.corrupt_revolution:
                data = corrupt_check_bit(data, len(self.lead_in) + 5 * 2)
            sent += 1
            if not self.pty.write(data):
                return
            self._done.wait(self.period)


def corrupt_check_bit(data: bytes, offset: int) -> bytes:
    """Clear the check bit (C = 1 on the line) of the sample starting at ``offset``."""
    damaged = bytearray(data)
    damaged[offset + 1] &= 0xFE
    return bytes(damaged)


@dataclass
class LdStreamer:
    """Streams LD packets, one burst per revolution period, until stopped or closed."""

    pty: Pty
    bursts: Callable[[int], bytes]  # burst number -> bytes
    period: float = 0.1
    _done: threading.Event = field(default_factory=threading.Event)

    def start(self) -> LdStreamer:
        self.pty.run(self._run)
        return self

    def stop(self) -> None:
        self._done.set()

    def _run(self) -> None:
        number = 0
        while not self._done.is_set():
            if not self.pty.write(self.bursts(number)):
                return
            number += 1
            self._done.wait(self.period)


# An endless LD19 stream at 10 Hz for the process tests (see point for its pattern).
POINTS_PER_TURN = 450  # 0.8 degree apart: an LD19 at 10 Hz
PACKETS_PER_BURST = 25  # 375 packets/s in bursts every 1/15 s, the device's own rate
BURST_PERIOD = PACKETS_PER_BURST / 375


def point(m: int) -> tuple[int, int]:
    """(distance mm, intensity) of the point at clockwise angle 0.8 * m degrees."""
    if m % 50 == 7:
        return 0, 0  # no return: NaN
    if m % 50 == 13:
        return 0, 100  # distance 0 with an intensity: the vendor driver publishes 0.0
    if m == 100:
        return 30000, 200  # beyond range_max: published as sent
    if m == 200:
        return 10, 200  # below range_min: published as sent
    return 500 + 10 * m, 200


def packet(i: int) -> bytes:
    """Packet ``i`` of an endless stream: points 12i..12i+11, 0.8 degree apart, 10 Hz."""
    start = (960 * i) % 36000
    points = [point((12 * i + k) % POINTS_PER_TURN) for k in range(12)]
    return ld_packet(3600, start, (start + 880) % 36000, points, timestamp_ms=(i * 3) % 30000)


def false_header(following: bytes) -> bytes:
    """A stray 54 2C and junk whose 47-byte window (into the real packet) fails the CRC."""
    for junk in range(256):
        noise = bytes([0x54, 0x2C, junk, 0x00, 0x54])
        window = (noise + following)[:47]
        if ld_crc8_bitwise(window[:46]) != window[46]:
            return noise
    raise AssertionError("unreachable: some junk byte always breaks the CRC")


def burst(number: int) -> bytes:
    """One burst of packets, led by noise the parser must resynchronise past."""
    first = number * PACKETS_PER_BURST
    data = b"".join(packet(i) for i in range(first, first + PACKETS_PER_BURST))
    return false_header(data) + data
