"""The toy LIDAR's protocol: one ASCII line a sample, streamed unasked (pure).

``<angle_cdeg>:<distance_mm>\\n``: the sample's clockwise angle in hundredths
of a degree and its distance in millimetres (0: no return). A sweep ends
where the angle wraps (as an LD06's does), so a host publishes a revolution
when the next one starts: the harness's start marker, the next sweep's first
sample, tells it. Each sample's bytes stand alone, as the harness's
"replace" start policy needs of a device that is not packetized.
"""

from __future__ import annotations

from collections.abc import Sequence

from harness.devices.protocol import DeviceDefaults
from harness.devices.revolution import Sample

BAUD = 460800
SAMPLES_PER_REV = 180  # one every 2 degrees


class ToyDevice(DeviceDefaults):
    """Streams from power-up; takes no requests, has no motor line (the defaults)."""

    mode = "streaming"
    bytes_per_sample = 12  # at most: "35800:12000\n"

    def encode_revolution(self, samples: Sequence[Sample], *, start_ms: float = 0.0) -> bytes:
        lines = (f"{round(s.angle_deg * 100) % 36000}:{round(s.distance_mm)}\n" for s in samples)
        return "".join(lines).encode("ascii")


def decode_line(line: bytes) -> tuple[float, float]:
    """One sample's (angle degrees, distance mm) from its line; ValueError if malformed."""
    angle, distance = line.decode("ascii").split(":")
    return int(angle) / 100.0, float(distance)
