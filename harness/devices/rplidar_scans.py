"""Slamtec RPLIDAR A1M8: the scan stream's two formats, as pure code.

Standard scans are 5-byte nodes (the start flag on the revolution's first);
legacy express scans 84-byte capsules of 32 samples whose angles come from
the next capsule's start. Each encoder has a slow, obvious reference
decoder (the vendor SDK's integer arithmetic) the tests check it against.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from functools import reduce
from operator import xor

from harness.devices.revolution import DEFAULT_QUALITY, Sample

NODE_LEN = 5
CAPSULE_LEN = 84
CABINS_PER_CAPSULE = 16
SAMPLES_PER_CAPSULE = 32
FULL_TURN_Q6 = 360 * 64
MAX_DISTANCE_Q2 = 0xFFFF
MAX_EXPRESS_DISTANCE_MM = 0x3FFF  # 14 bits
MAX_ANGLE_OFFSET_Q3 = 31  # dtheta kept in 0..31 so signed and unsigned readers agree


def xor_all(data: bytes | bytearray) -> int:
    """The protocol's checksum: every byte xor-ed (requests and express capsules)."""
    return reduce(xor, data, 0)


# -- standard scan nodes --------------------------------------------------------


def _angle_q6(angle_deg: float) -> int:
    """Degrees to q6 in [0, 360 * 64): an angle just under 360 stays the last step."""
    return min(int(round((angle_deg % 360.0) * 64)), FULL_TURN_Q6 - 1)


def _distance_q2(distance_mm: float) -> int:
    return min(max(int(round(distance_mm * 4)), 0), MAX_DISTANCE_Q2)


def encode_node(sample: Sample, *, start: bool) -> bytes:
    """One standard-scan node: quality<<2 | !S<<1 | S; angle_q6<<1 | 1; distance_q2 (LE)."""
    dist = _distance_q2(sample.distance_mm)
    quality = min(max(int(sample.quality), 0), 63) if dist else 0
    flags = 0b01 if start else 0b10
    return struct.pack("<BHH", (quality << 2) | flags, (_angle_q6(sample.angle_deg) << 1) | 1, dist)


def encode_standard(samples: Sequence[Sample]) -> bytes:
    """One revolution of nodes, the smallest angle (where the device wraps) flagged as the start."""
    if not samples:
        return b""
    ordered = list(samples)
    first = min(range(len(ordered)), key=lambda i: _angle_q6(ordered[i].angle_deg))
    ordered = ordered[first:] + ordered[:first]
    return b"".join(encode_node(s, start=(i == 0)) for i, s in enumerate(ordered))


def decode_standard(data: bytes) -> list[Sample]:
    """Reference decoder for standard nodes; raises ValueError on a broken node."""
    return [sample for sample, _ in decode_standard_nodes(data)]


def decode_standard_nodes(data: bytes) -> list[tuple[Sample, bool]]:
    """(sample, start flag) for each 5-byte node, checking S != !S and the check bit."""
    if len(data) % NODE_LEN:
        raise ValueError(f"{len(data)} bytes is not a whole number of {NODE_LEN}-byte nodes")
    nodes = []
    for offset in range(0, len(data), NODE_LEN):
        b0, angle_field, dist_q2 = struct.unpack_from("<BHH", data, offset)
        start, not_start = b0 & 1, (b0 >> 1) & 1
        if start == not_start:
            raise ValueError(f"node at {offset}: start flag and its inverse agree")
        if not angle_field & 1:
            raise ValueError(f"node at {offset}: check bit is 0")
        sample = Sample((angle_field >> 1) / 64.0, dist_q2 / 4.0, b0 >> 2)
        nodes.append((sample, bool(start)))
    return nodes


# -- legacy express capsules ----------------------------------------------------


def _angle_diff_q6(start_q6: int, next_q6: int) -> int:
    """AngleDiff of the protocol: next - start, plus a turn when it wraps."""
    diff = next_q6 - start_q6
    return diff + FULL_TURN_Q6 if diff < 0 else diff


def _angle_offset_q3(raw_q16: int, angle_deg: float) -> int:
    """The compensation dtheta (q3 degrees) that moves a raw angle onto the sample's."""
    delta = (raw_q16 / 65536.0 - angle_deg + 180.0) % 360.0 - 180.0
    return min(max(int(round(delta * 8)), 0), MAX_ANGLE_OFFSET_Q3)


def encode_capsule(
    samples: Sequence[Sample], next_start_deg: float, *, start_flag: bool = False
) -> bytes:
    """One 84-byte express capsule holding 32 samples.

    Sample k sits at start + k * AngleDiff / 32 - dtheta_k, the host learning
    AngleDiff from the next capsule's start; dtheta is kept in 0..31 (0..3.875
    deg), where the protocol's signed reading and the SDK's unsigned agree.
    """
    if len(samples) != SAMPLES_PER_CAPSULE:
        raise ValueError(f"a capsule holds {SAMPLES_PER_CAPSULE} samples, got {len(samples)}")
    start_q6 = _angle_q6(samples[0].angle_deg)
    inc_q16 = _angle_diff_q6(start_q6, _angle_q6(next_start_deg)) << 5  # diff / 32, in q16
    body = bytearray(struct.pack("<H", start_q6 | (0x8000 if start_flag else 0)))
    for cabin in range(CABINS_PER_CAPSULE):
        fields = []
        for k in (2 * cabin, 2 * cabin + 1):
            sample = samples[k]
            raw_q16 = (start_q6 << 10) + k * inc_q16
            dist = min(max(int(round(sample.distance_mm)), 0), MAX_EXPRESS_DISTANCE_MM)
            fields.append((dist, _angle_offset_q3(raw_q16, sample.angle_deg)))
        (d1, t1), (d2, t2) = fields
        offsets = (t1 & 0xF) | ((t2 & 0xF) << 4)
        body += struct.pack("<HHB", (d1 << 2) | (t1 >> 4), (d2 << 2) | (t2 >> 4), offsets)
    checksum = xor_all(body)
    return bytes((0xA0 | (checksum & 0xF), 0x50 | (checksum >> 4))) + bytes(body)


def _check_capsule(capsule: bytes) -> None:
    if len(capsule) != CAPSULE_LEN:
        raise ValueError(f"a capsule is {CAPSULE_LEN} bytes, got {len(capsule)}")
    if capsule[0] >> 4 != 0xA or capsule[1] >> 4 != 0x5:
        raise ValueError("capsule sync nibbles are not 0xA, 0x5")
    checksum = (capsule[0] & 0xF) | ((capsule[1] & 0xF) << 4)
    if checksum != xor_all(capsule[2:]):
        raise ValueError("capsule checksum mismatch")


def capsule_start_angle_q6(capsule: bytes) -> int:
    return struct.unpack_from("<H", capsule, 2)[0] & 0x7FFF


def capsule_start_flag(capsule: bytes) -> bool:
    """S: set only on the first capsule after EXPRESS_SCAN (or after a restart)."""
    return bool(struct.unpack_from("<H", capsule, 2)[0] & 0x8000)


def decode_express(capsule_a: bytes, capsule_b: bytes) -> list[Sample]:
    """Reference decoder: capsule_a's 32 samples, using capsule_b's start angle.

    Integer arithmetic as in the vendor SDK (q16 angles, dtheta unsigned), so
    the results match ``rplidar_ros``'s.
    """
    _check_capsule(capsule_a)
    _check_capsule(capsule_b)
    start_q6 = capsule_start_angle_q6(capsule_a)
    inc_q16 = _angle_diff_q6(start_q6, capsule_start_angle_q6(capsule_b)) << 5
    raw_q16 = start_q6 << 10
    samples = []
    for cabin in range(CABINS_PER_CAPSULE):
        word1, word2, offsets = struct.unpack_from("<HHB", capsule_a, 4 + 5 * cabin)
        for word, nibble in ((word1, offsets & 0xF), (word2, offsets >> 4)):
            dist_q2 = word & 0xFFFC
            dtheta_q3 = nibble | ((word & 0x3) << 4)
            angle_q6 = ((raw_q16 - (dtheta_q3 << 13)) >> 10) % FULL_TURN_Q6
            raw_q16 += inc_q16
            quality = DEFAULT_QUALITY if dist_q2 else 0
            samples.append(Sample(angle_q6 / 64.0, dist_q2 / 4.0, quality))
    return samples
