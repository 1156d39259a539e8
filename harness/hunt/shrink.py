"""Simpler versions of a failing candidate, simplest change first (pure).

Each round keeps the first that still fails the same way; shrinking ends
when none does. The order: no sensor fault, REP-117, no obstacle, standing
still, a shorter run, the Gazebo preset, rounder numbers.
"""

from __future__ import annotations

import math
from dataclasses import replace

from harness.hunt.space import Candidate

Step = tuple[str, Candidate]  # what changed, in words, and the simpler candidate

DURATIONS = (0.2, 0.5, 1.0)  # s, tried shortest first
#: name -> the steps of its rounder values, coarsest first.
ROUND_STEPS: dict[str, tuple[float, ...]] = {
    "threshold": (0.5, 0.1, 0.05, 0.01, 0.005, 0.001),  # 0.5 m: the lab's, tried as is
    "distance": (1.0, 0.5, 0.1, 0.05, 0.01, 0.005, 0.001),
    "size": (1.0, 0.5, 0.1, 0.05, 0.01),
    "speed": (0.1, 0.05, 0.01),
    "fault_rate": (0.1, 0.05, 0.01),
    "duration": (0.5, 0.1),
}
#: name -> (the field that must be on for it to matter, that field's off value).
_SIZES = {name: ("obstacle", "none") for name in ("distance", "size")}
_SIZES |= {"speed": ("motion", "still"), "fault_rate": ("fault", "none")}
BEARINGS = (0.0, math.pi / 2, -math.pi / 2, math.pi, math.pi / 4, -math.pi / 4)


def simplifications(candidate: Candidate) -> list[Step]:
    """Every one-change simpler version of `candidate`, in the order to try them."""
    steps: list[Step] = []

    def offer(what: str, **changes: object) -> None:
        simpler = replace(candidate, **changes)  # type: ignore[arg-type]
        if simpler != candidate and all(simpler != s for _, s in steps):
            steps.append((what, simpler))

    # A change that leaves the candidate as it is offers nothing (see offer).
    offer("no sensor fault", fault="none")
    offer("the REP-117 convention (+inf for no return)", convention="rep117")
    offer("no obstacle", obstacle="none")
    offer("standing still", motion="still")
    for duration in DURATIONS:
        if duration < candidate.duration - 1e-9:
            offer(f"{duration:g} s long", duration=duration)
    offer("the gazebo LIDAR preset", preset="gazebo")
    offer("threshold 0.5 m", threshold=0.5)
    round_bearing = any(abs(candidate.bearing - b) < 1e-9 for b in BEARINGS)
    if candidate.obstacle != "none" and not round_bearing:
        for bearing in BEARINGS:
            if abs(candidate.bearing - bearing) > 1e-9:
                offer(f"bearing {bearing:.4g} rad", bearing=bearing)
    for name, units in ROUND_STEPS.items():
        if not _applies(candidate, name):
            continue
        value = getattr(candidate, name)
        for unit in units:
            rounder = _rounded(value, unit)
            if rounder is not None and rounder != value and _digits(rounder) < _digits(value):
                offer(f"{name} {rounder:g}", **{name: rounder})
    return steps


def _applies(candidate: Candidate, name: str) -> bool:
    """Does `name` change the scenario of `candidate`? Not while what it sizes is off."""
    field, off = _SIZES.get(name, ("", None))
    return not field or getattr(candidate, field) != off


def _rounded(value: float, unit: float) -> float | None:
    """`value` to the nearest multiple of `unit` (None when that is 0 or less)."""
    rounder = round(round(value / unit) * unit, 6)
    return rounder if rounder > 0 else None


def _digits(value: float) -> int:
    """Decimal places `value` needs (up to 6)."""
    for places in range(7):
        if abs(value - round(value, places)) < 1e-9:
            return places
    return 7
