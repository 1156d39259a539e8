"""Pure figures for the bench: percentiles, ratios, overhead, line rates (no I/O).

Kept apart from the stages so the formulas the report quotes are in one
place and testable in milliseconds.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from itertools import accumulate, pairwise
from statistics import median

__all__ = [
    "RPLIDAR_NODE_BYTES", "RPLIDAR_SCAN_DESCRIPTOR", "arrival_rate", "jitter_ms", "jitter_p99_ms",
    "median", "overhead_ratio", "percentile", "read_times", "rplidar_revolution_starts",
]  # fmt: skip

#: The RPLIDAR's reply descriptor to SCAN: 0xA5 0x5A, 5-byte nodes, multiple response, type 0x81.
RPLIDAR_SCAN_DESCRIPTOR = bytes((0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81))
RPLIDAR_NODE_BYTES = 5


def percentile(values: Sequence[float], q: float) -> float:
    """Nearest-rank percentile, `q` in (0, 100]: a value that occurred, never interpolated
    (with fewer than 100 values the 99th is the maximum)."""
    if not values:
        raise ValueError("percentile of no values")
    if not 0 < q <= 100:
        raise ValueError(f"q must be in (0, 100], got {q}")
    ordered = sorted(values)
    return ordered[max(0, math.ceil(q / 100.0 * len(ordered)) - 1)]


def overhead_ratio(scan_s: float, raycast_s: float, round_trip_s: float) -> float:
    """Harness time per lockstep scan beyond ray casting and the median DDS round trip, as
    a fraction of them: 0 means it adds nothing to the two costs it cannot avoid."""
    floor = raycast_s + round_trip_s
    if floor <= 0:
        raise ValueError("ray casting plus round trip must take some time")
    return (scan_s - floor) / floor


def jitter_ms(starts_s: Sequence[float], period_s: float) -> list[float]:
    """|start-to-start interval - period| of each interval, in ms."""
    return [abs((b - a) - period_s) * 1000.0 for a, b in pairwise(starts_s)]


def jitter_p99_ms(starts_s: Sequence[float], period_s: float) -> float | None:
    """p99 of |start-to-start interval - period|, in ms (None for fewer than two starts)."""
    jitter = jitter_ms(starts_s, period_s)
    return percentile(jitter, 99) if jitter else None


def rplidar_revolution_starts(data: bytes) -> list[int]:
    """Byte offsets of the revolution-start nodes (start flag S set, bit 0, its inverse
    bit 1 clear) in an RPLIDAR standard scan stream, SCAN reply descriptor first."""
    head = RPLIDAR_SCAN_DESCRIPTOR
    if not data.startswith(head):
        raise ValueError("the stream does not start with the RPLIDAR scan descriptor")
    offsets = range(len(head), len(data) - RPLIDAR_NODE_BYTES + 1, RPLIDAR_NODE_BYTES)
    return [offset for offset in offsets if data[offset] & 0b11 == 0b01]


def read_times(reads: Sequence[tuple[float, int]], offsets: Sequence[int]) -> list[float]:
    """When the reader had each byte offset: the time of the read that brought it."""
    totals = list(accumulate(n for _, n in reads))
    times = []
    for offset in offsets:
        k = bisect.bisect_right(totals, offset)
        if k == len(totals):
            break
        times.append(reads[k][0])
    return times


def arrival_rate(
    reads: Sequence[tuple[float, int]], segments: Sequence[tuple[int, int]]
) -> float | None:
    """Bytes per second inside busy stretches, as the reader saw them arrive: for each
    byte range [start, end) sent back to back, what came between its first and last read
    (`reads`: (time, bytes) in order), so idle gaps never count; None without two reads."""
    ends = list(zip((t for t, _ in reads), accumulate(n for _, n in reads), strict=True))
    got_bytes = got_time = 0.0
    for lo, hi in segments:
        inside = [(t, e) for t, e in ends if lo < e < hi]
        if len(inside) >= 2:
            (t1, e1), (t2, e2) = inside[0], inside[-1]
            got_bytes += e2 - e1
            got_time += t2 - t1
    return got_bytes / got_time if got_time > 0 else None
