"""
Grouping a LIDAR's sample stream into revolutions (pure Python and numpy).

A revolution is complete only when the next one starts, so each splitter
hands back revolution ``n`` when it sees the first sample of ``n + 1``: one
revolution of latency, as on the real device. Samples before the first
start (a partial turn) are counted and dropped, so every published scan is
a full turn with a measured duration.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

__all__ = ['LdRevolutionSplitter', 'Revolution', 'RplidarRevolutionSplitter']


@dataclass(frozen=True)
class Revolution:
    """One full turn of samples, in arrival order, and when it started and ended."""

    angles_deg: np.ndarray
    distances_mm: np.ndarray
    intensities: np.ndarray  # RPLIDAR quality or LD intensity
    start: float  # arrival time of its first sample (seconds, monotonic clock)
    end: float  # arrival time of the next revolution's first sample

    @property
    def duration(self) -> float:
        """Return the measured time of the turn in seconds."""
        return self.end - self.start

    def __len__(self) -> int:
        """Return the number of samples, returns or not."""
        return int(self.angles_deg.size)


@dataclass
class _Accumulator:
    """Samples of the revolution in progress."""

    start: float | None = None
    angles: list[float] = field(default_factory=list)
    distances: list[float] = field(default_factory=list)
    intensities: list[int] = field(default_factory=list)

    def close(self, end: float) -> Revolution:
        """Return the samples so far as a Revolution ending at ``end``."""
        assert self.start is not None
        return Revolution(
            np.asarray(self.angles, dtype=np.float64),
            np.asarray(self.distances, dtype=np.float64),
            np.asarray(self.intensities, dtype=np.int64),
            self.start,
            end,
        )

    def restart(self, start: float) -> None:
        """Begin a new revolution at ``start``."""
        self.start = start
        self.angles.clear()
        self.distances.clear()
        self.intensities.clear()


class RplidarRevolutionSplitter:
    """Split RPLIDAR standard-scan samples at the start flag (S bit)."""

    def __init__(self) -> None:
        """Start before any revolution: samples are dropped until a start flag."""
        self._current = _Accumulator()
        self.dropped = 0

    def add(
        self, new_scan: bool, quality: int, angle_deg: float, distance_mm: float, t: float
    ) -> Revolution | None:
        """Take one sample; return the revolution its start flag completed, if any."""
        done = None
        if new_scan:
            if self._current.start is not None:
                done = self._current.close(t)
            self._current.restart(t)
        if self._current.start is None:
            self.dropped += 1
            return None
        self._current.angles.append(angle_deg)
        self._current.distances.append(distance_mm)
        self._current.intensities.append(quality)
        return done


class LdRevolutionSplitter:
    """
    Split LD06/LD19 points where the angle wraps past 360 degrees.

    A wrap is a drop of more than 180 degrees from one point to the next
    (the vendor SDK asks for "below 20 after above 340"; the same at any
    realistic speed, and independent of it). All points of one packet share
    the packet's arrival time.
    """

    def __init__(self) -> None:
        """Start before any revolution: points are dropped until the first wrap."""
        self._current = _Accumulator()
        self._last_angle: float | None = None
        self.dropped = 0

    def add_packet(
        self,
        angles_deg: npt.ArrayLike,
        distances_mm: npt.ArrayLike,
        intensities: npt.ArrayLike,
        t: float,
    ) -> list[Revolution]:
        """Take one packet's points; return the revolutions they completed (usually none)."""
        done: list[Revolution] = []
        for angle, distance, intensity in zip(
            np.asarray(angles_deg, dtype=np.float64).tolist(),
            np.asarray(distances_mm).tolist(),
            np.asarray(intensities).tolist(),
            strict=True,
        ):
            if self._last_angle is not None and angle < self._last_angle - 180.0:
                if self._current.start is not None:
                    done.append(self._current.close(t))
                self._current.restart(t)
            self._last_angle = angle
            if self._current.start is None:
                self.dropped += 1
                continue
            self._current.angles.append(angle)
            self._current.distances.append(distance)
            self._current.intensities.append(intensity)
        return done
