"""LIDAR geometry and timing presets (pure data).

A ``LidarSpec`` says where the beams point and how far they see; the
simulator casts one ray per beam and the fault stage turns the truth into
what a given driver would publish.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from harness.errors import ConfigError

if TYPE_CHECKING:
    import numpy as np

    from harness.lidar.scan import Scan

# rad: how far a layout may pass one turn (or +-2 pi) by rounding: an
# angle_increment taken from a float32 LaserScan, times 16383 beams, is off by
# well under this; a typed increment of 6 significant digits may be more.
ANGLE_TOLERANCE = 1e-5


@dataclass(frozen=True)
class LidarSpec:
    """Beam layout of one revolution, in the LIDAR frame (REP-103: CCW, x forward)."""

    name: str
    samples: int
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    rate_hz: float

    @property
    def angle_max(self) -> float:
        return self.angle_min + (self.samples - 1) * self.angle_increment

    @property
    def scan_time(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def time_increment(self) -> float:
        return self.scan_time / self.samples

    def scan(self, ranges: np.ndarray, **fields: Any) -> Scan:
        """A scan of this layout holding `ranges` (and `fields`: intensities, stamp, ...)."""
        from harness.lidar.scan import FLOATS, Scan  # numpy: not for those who only read presets

        return Scan(**{name: getattr(self, name) for name in FLOATS}, ranges=ranges, **fields)

    def with_overrides(self, **changes: float | int | None) -> LidarSpec:
        """A copy with the given fields replaced (None means keep)."""
        kept = {k: v for k, v in changes.items() if v is not None}
        spec = replace(self, **kept)
        spec.check()
        return spec

    def check(self) -> None:
        """Refuse layouts no real sensor has.

        At most one turn ((samples - 1) x increment <= 2 pi: Gazebo's closed
        layout is the most), every angle within +-2 pi, where the oracle's
        "any wrap" comparison holds.
        """
        if not 1 <= self.samples <= 16383:
            raise ConfigError(f"lidar samples must be 1..16383, got {self.samples}")
        if not (0 < self.range_min < self.range_max):
            raise ConfigError(
                f"lidar needs 0 < range_min < range_max, got {self.range_min}..{self.range_max}"
            )
        if not self.rate_hz > 0:
            raise ConfigError(f"lidar rate_hz must be positive, got {self.rate_hz}")
        if not self.angle_increment > 0:
            raise ConfigError(f"lidar angle_increment must be positive, got {self.angle_increment}")
        turn = 2 * math.pi
        span = (self.samples - 1) * self.angle_increment
        if span > turn + ANGLE_TOLERANCE:
            raise ConfigError(
                f"the beams span (samples - 1) x angle_increment = {self.samples - 1} x "
                f"{self.angle_increment:.6g} = {span:.6g} rad, more than one turn "
                f"(2 pi = {turn:.6g} rad): fewer samples or a smaller angle_increment"
            )
        if not -turn - ANGLE_TOLERANCE <= self.angle_min <= turn + ANGLE_TOLERANCE:
            raise ConfigError(f"angle_min must be within +-2 pi, got {self.angle_min:.6g} rad")
        if self.angle_max > turn + ANGLE_TOLERANCE:
            raise ConfigError(
                f"the last beam's angle, angle_min + (samples - 1) x angle_increment = "
                f"{self.angle_min:.6g} + {span:.6g} = {self.angle_max:.6g} rad, is beyond 2 pi "
                f"({turn:.6g}); beam angles must stay within +-2 pi (a smaller angle_min)"
            )


def _full_circle(samples: int, *, closed: bool) -> float:
    """Increment for `samples` beams over a full turn; `closed` repeats the first angle."""
    return 2 * math.pi / (samples - 1 if closed else samples)


PRESETS: dict[str, LidarSpec] = {
    spec.name: spec
    for spec in (
        # name, samples, angle_min, angle_increment, range_min, range_max, rate_hz.
        # The lab's simulator (public FOSSBot Gazebo model): 360 samples from -pi
        # to pi inclusive, as Gazebo spaces them ((max - min) / (samples - 1)).
        LidarSpec("gazebo", 360, -math.pi, _full_circle(360, closed=True), 0.12, 12.0, 10.0),
        # Slamtec RPLIDAR A1M8 as the FOSSBot v2 bridge publishes it: 360 one-degree
        # bins, 0 .. 2*pi - step.
        LidarSpec("rplidar_a1", 360, 0.0, _full_circle(360, closed=False), 0.15, 12.0, 5.5),
        # LDROBOT LD19/LD06: 4500 samples/s at 10 Hz = 450 points per turn.
        LidarSpec("ld19", 450, 0.0, _full_circle(450, closed=False), 0.02, 12.0, 10.0),
    )
}


def add_preset(spec: LidarSpec) -> LidarSpec:
    """Make a LIDAR preset from outside the harness known by its name (once); returns it."""
    known = PRESETS.get(spec.name)
    if known is not None and known != spec:
        raise RuntimeError(f"lidar preset {spec.name!r} is defined twice")
    spec.check()
    PRESETS[spec.name] = spec
    return spec


def preset(name: str) -> LidarSpec:
    """The named preset, or a ConfigError listing the known ones."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(PRESETS))
        raise ConfigError(f"unknown lidar preset {name!r} (known: {known})") from None
