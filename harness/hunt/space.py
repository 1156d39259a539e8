"""The scenarios a hunt searches: one point of the space is one short scenario (pure).

A ``Candidate`` is at most one obstacle relative to the start, one motion
segment, the LIDAR preset, the driver's convention, at most one sensor
fault and the threshold; ``suggest`` draws one from an optimiser's trial
(duck typed). Motion is cut short where the robot's outline would come
within ``CLEARANCE_M`` of the obstacle, so a real robot could drive it.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any, Protocol

from harness.scenario.footprint import Outline, overlap, robot_outlines
from harness.scenario.model_files import parse_xml, robot_models_dir
from harness.scenario.schema import Box, Cylinder, RobotConfig, Wall

OBSTACLES = ("none", "wall", "box", "cylinder")
MOTIONS = ("still", "straight", "reverse", "turn")
PRESETS = ("gazebo", "rplidar_a1")  # angle_min -pi (Gazebo) and 0 (the FOSSBot v2's RPLIDAR)
#: The driver's conventions, and how each gives no return.
CONVENTIONS = {"rep117": "no return as +inf", "zero": "no return as 0.0", "nan": "no return as NaN"}
FAULTS = ("none", "noise", "dropouts", "spurious", "far_returns")

#: name -> (low, high) of each number drawn.
RANGES: dict[str, tuple[float, float]] = {
    "distance": (0.05, 14.0),  # m from the robot's start to the obstacle's nearest face
    "bearing": (-math.pi, math.pi),  # rad, 0 straight ahead, counter-clockwise
    "size": (0.05, 3.0),  # m: a wall's length, a box's side, a cylinder's diameter
    "speed": (0.05, 0.5),  # m/s; a turn at 4x that in rad/s
    "duration": (0.2, 2.0),  # s of the one motion segment: a run costs about 0.1 s a tick
    "fault_rate": (0.01, 0.3),  # a rate; noise sigma is a tenth of it in metres
    "threshold": (0.2, 1.5),  # m
}
#: Drawn on a log scale: a centimetre matters near the robot, not 10 m away.
LOG_SCALED = frozenset({"distance", "size", "fault_rate"})
TURN_PER_SPEED = 4.0  # rad/s of a turn per m/s of `speed`
NOISE_PER_RATE = 0.1  # m of noise sigma per unit of fault_rate
WALL_THICKNESS = 0.05
OBSTACLE_HEIGHT = 0.5
CLEARANCE_M = 0.03  # the robot's outline keeps this far from the obstacle while it moves
_STEP_M = 0.01  # path sampling when cutting a motion short
_STEP_RAD = 0.02
_MAX_PUSHES = 1000  # 10 m of centimetre steps: farther than any robot reaches
MIN_DURATION = 0.1  # s: a segment cut shorter than this stands still instead
DRIVER_FAULTS = {"zero": "driver_zero", "nan": "driver_nan"}  # rep117 is the default


@dataclass(frozen=True)
class Candidate:
    """One point of the space; numbers that do not apply (a size with no obstacle) are ignored."""

    obstacle: str = "none"
    distance: float = 1.0
    bearing: float = 0.0
    size: float = 1.0
    motion: str = "still"
    speed: float = 0.2
    duration: float = 0.5
    preset: str = "gazebo"
    convention: str = "rep117"
    fault: str = "none"
    fault_rate: float = 0.05
    threshold: float = 0.5

    def as_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def describe(self) -> str:
        """One line: what the scenario holds and does."""
        at = f"{self.size:.3g} m at {self.distance:.3g} m, bearing {self.bearing:.3g} rad"
        parts = ["no obstacle" if self.obstacle == "none" else f"{self.obstacle} {at}"]
        if self.motion == "still":
            parts.append(f"standing {self.duration:.3g} s")
        else:
            turn = self.motion == "turn"
            rate, unit = (self.speed * TURN_PER_SPEED, "rad/s") if turn else (self.speed, "m/s")
            how = "turning" if turn else self.motion
            parts.append(f"{how} {rate:.3g} {unit} for {self.duration:.3g} s")
        parts.append(f"{self.preset} LIDAR, {CONVENTIONS[self.convention]}")
        if self.fault != "none":
            parts.append(_fault_words(self))
        parts.append(f"threshold {self.threshold:.3g} m")
        return "; ".join(parts)


class Trial(Protocol):
    """What ``suggest`` asks of an optimiser's trial (optuna.Trial has these)."""

    def suggest_categorical(self, name: str, choices: Sequence[Any]) -> Any: ...

    def suggest_float(self, name: str, low: float, high: float, *, log: bool = False) -> float: ...


def suggest(trial: Trial) -> Candidate:
    """A candidate drawn by `trial`; numbers that do not apply are not asked for, so the
    optimiser learns nothing false about them."""
    choices = {"obstacle": OBSTACLES, "motion": MOTIONS, "preset": PRESETS}
    choices |= {"convention": tuple(CONVENTIONS), "fault": FAULTS}
    drawn: dict[str, Any] = {k: trial.suggest_categorical(k, v) for k, v in choices.items()}
    wanted = ["duration", "threshold"]
    if drawn["obstacle"] != "none":
        wanted += ["distance", "bearing", "size"]
    if drawn["motion"] != "still":
        wanted.append("speed")
    if drawn["fault"] != "none":
        wanted.append("fault_rate")
    for name in wanted:
        drawn[name] = trial.suggest_float(name, *RANGES[name], log=name in LOG_SCALED)
    return Candidate(**drawn)


def obstacle_outline(candidate: Candidate) -> Outline | None:
    """The obstacle's footprint, placed from the robot's start (at the origin, facing +x):
    the scenario schema's own outline of its file entry."""
    entry = obstacle_entry(candidate)
    if entry is None:
        return None
    kind = {"wall": Wall, "box": Box, "cylinder": Cylinder}[entry["type"]]
    return kind.model_validate(entry).outline()


def obstacle_entry(candidate: Candidate) -> dict[str, Any] | None:
    """The scenario file's entry for the obstacle (None without one): its nearest face
    `distance` from the start along `bearing`, facing the robot."""
    if candidate.obstacle == "none":
        return None
    b, d, size = candidate.bearing, candidate.distance, candidate.size
    way = (math.cos(b), math.sin(b))
    across = (-way[1], way[0])
    if candidate.obstacle == "wall":
        centre = _along(way, d + WALL_THICKNESS / 2)
        half = size / 2
        return {
            "type": "wall",
            "start": _round_point((centre[0] - across[0] * half, centre[1] - across[1] * half)),
            "end": _round_point((centre[0] + across[0] * half, centre[1] + across[1] * half)),
            "thickness": WALL_THICKNESS,
            "height": OBSTACLE_HEIGHT,
        }
    if candidate.obstacle == "box":
        return {
            "type": "box",
            "position": _round_point(_along(way, d + size / 2)),
            "size": [_round(size), _round(size), OBSTACLE_HEIGHT],
            "yaw": _round(b),
        }
    return {
        "type": "cylinder",
        "position": _round_point(_along(way, d + size / 2)),
        "radius": _round(size / 2),
        "height": OBSTACLE_HEIGHT,
    }


@functools.cache
def robot_footprint() -> tuple[Outline, ...]:
    """The default robot's outline at the origin, as the start check reads it (once a process)."""
    urdf = RobotConfig().urdf
    return tuple(robot_outlines(parse_xml(robot_models_dir() / urdf, f"robot model {urdf!r}")))


def placed(candidate: Candidate, robot: Sequence[Outline]) -> Candidate:
    """`candidate` with its obstacle pushed out along its bearing, in centimetre steps,
    until the robot's outline `robot` (at the start) keeps CLEARANCE_M from it: a robot
    cannot start inside or against what it is to see."""
    if candidate.obstacle == "none" or not robot:
        return candidate
    distance = candidate.distance
    for _ in range(_MAX_PUSHES):
        moved = replace(candidate, distance=_round(distance))
        outline = obstacle_outline(moved)
        assert outline is not None
        if max(overlap(part, outline) for part in robot) <= -CLEARANCE_M:
            return moved
        distance += _STEP_M
    return moved


def clear_duration(candidate: Candidate, robot: Sequence[Outline]) -> float:
    """How long the candidate's motion may last before the robot's outline `robot` (placed
    at the origin) comes within CLEARANCE_M of the obstacle: its duration, or less."""
    outline = obstacle_outline(candidate)
    if outline is None or candidate.motion == "still" or not robot:
        return candidate.duration
    if candidate.motion == "turn":
        rate = candidate.speed * TURN_PER_SPEED
        step = _STEP_RAD / rate
    else:
        step = _STEP_M / candidate.speed
    heading = -1.0 if candidate.motion == "reverse" else 1.0
    t = 0.0
    while t < candidate.duration:
        nxt = min(t + step, candidate.duration)
        if candidate.motion == "turn":
            pose = (0.0, 0.0, candidate.speed * TURN_PER_SPEED * nxt)
        else:
            pose = (heading * candidate.speed * nxt, 0.0, 0.0)
        if max(overlap(part.placed(*pose), outline) for part in robot) > -CLEARANCE_M:
            return t
        t = nxt
    return candidate.duration


def motion_segment(candidate: Candidate, duration: float) -> dict[str, Any]:
    """The one motion segment, lasting `duration` (already cut to stay clear)."""
    until = {"duration": _round(duration)}
    if candidate.motion == "still" or duration < MIN_DURATION:
        return {"until": {"duration": _round(max(duration, MIN_DURATION))}}
    if candidate.motion == "turn":
        return {"angular": _round(candidate.speed * TURN_PER_SPEED), "until": until}
    sign = -1.0 if candidate.motion == "reverse" else 1.0
    return {"linear": _round(sign * candidate.speed), "until": until}


def fault_entries(candidate: Candidate) -> list[Any]:
    """The scenario's `faults:` list: the driver's convention, then the one fault."""
    entries: list[Any] = []
    if candidate.convention in DRIVER_FAULTS:
        entries.append(DRIVER_FAULTS[candidate.convention])
    rate = _round(candidate.fault_rate)
    if candidate.fault == "noise":
        entries.append({"type": "noise", "sigma": _round(candidate.fault_rate * NOISE_PER_RATE)})
    elif candidate.fault == "dropouts":
        entries.append({"type": "dropouts", "rate": rate, "value": "nan"})
    elif candidate.fault in ("spurious", "far_returns"):
        entries.append({"type": candidate.fault, "rate": rate})
    return entries


def scenario_document(
    candidate: Candidate, robot: Sequence[Outline], *, description: str, seed: int = 0
) -> dict[str, Any]:
    """The scenario file's contents for `candidate` (a mapping a YAML dump writes as is)."""
    document: dict[str, Any] = {
        "description": description,
        "lidar": {"preset": candidate.preset},
        "obstacles": [e for e in (obstacle_entry(candidate),) if e is not None],
        "motion": {"segments": [motion_segment(candidate, clear_duration(candidate, robot))]},
        "faults": fault_entries(candidate),
        "threshold": _round(candidate.threshold),
        "seed": seed,
    }
    for key in ("obstacles", "faults"):  # the simplest file leaves out what is empty
        if not document[key]:
            del document[key]
    return document


def _along(way: tuple[float, float], length: float) -> tuple[float, float]:
    return (way[0] * length, way[1] * length)


def _round(value: float) -> float:
    """Four decimals: a readable file, and the same file for the same candidate."""
    return round(float(value), 4) + 0.0  # + 0.0: no -0.0 in a file


def _round_point(point: tuple[float, float]) -> list[float]:
    return [_round(point[0]), _round(point[1])]


def _fault_words(candidate: Candidate) -> str:
    if candidate.fault == "noise":
        return f"noise sigma {candidate.fault_rate * NOISE_PER_RATE:.3g} m"
    return f"{candidate.fault} {candidate.fault_rate:.0%}"
