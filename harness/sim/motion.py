"""Motion scripts: which body velocity holds when, and how the robot follows it.

The pure part (no pybullet) is the unicycle integration and the segment
bookkeeping, so it unit-tests in milliseconds. ``duration``, ``distance``
and ``turn`` conditions are turned into exact segment times up front
(distance / |linear|, turn / |angular|), so segments end exactly, even
between two scans. ``obstacle_ahead_*`` conditions can only be judged on a
scan, so they are checked once per LIDAR revolution.

Two drivers move the robot in a world: ``KinematicDriver`` sets the pose
exactly (default; exact, no physics), ``WheelDriver`` commands the wheel
motors and steps the physics at a fixed 240 Hz (slip, bumps, inertia). In
wheels mode distance and turn conditions still count the commanded motion,
as a timed open-loop command on the real robot would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from harness.errors import ConfigError
from harness.safe_text import shown
from harness.scenario.schema import WHEEL_JOINTS, Motion, Segment

EPS_TIME = 1e-9  # s; segment ends closer than this to a step boundary fall on it
WHEEL_MAX_TORQUE = 0.5  # N m per wheel motor in wheels mode
SETTLE_STEPS = 24  # physics steps (0.1 s) the robot rests on its wheels before t = 0


@dataclass(frozen=True)
class Pose:
    """A planar pose: metres and radians (yaw CCW from +x, in (-pi, pi])."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class WheelGeometry:
    """What wheels mode needs to turn (v, w) into joint velocities."""

    left_joint: int
    right_joint: int
    radius: float  # m
    track: float  # m, distance between the wheel contact points
    left_sign: int  # +1 if a positive joint velocity rolls the left wheel forward
    right_sign: int


class Piece(NamedTuple):
    """A stretch of constant body velocity."""

    duration: float  # s
    linear: float  # m/s
    angular: float  # rad/s


def wrap_angle(angle: float) -> float:
    """The same direction in [-pi, pi]."""
    return math.remainder(angle, 2.0 * math.pi)


def integrate(pose: Pose, linear: float, angular: float, dt: float) -> Pose:
    """Exact unicycle motion for constant (v, w) over dt: a chord of length
    v*dt*sinc(w*dt/2) at the mean heading, the arc written to stay accurate as w -> 0."""
    half = angular * dt / 2.0
    chord = linear * dt * (math.sin(half) / half if abs(half) > 1e-12 else 1.0)
    heading = pose.yaw + half
    return Pose(
        pose.x + chord * math.cos(heading),
        pose.y + chord * math.sin(heading),
        wrap_angle(pose.yaw + 2.0 * half),
    )


def integrate_pieces(pose: Pose, pieces: list[Piece]) -> Pose:
    """Pose after the pieces, one after the other."""
    for piece in pieces:
        pose = integrate(pose, piece.linear, piece.angular, piece.duration)
    return pose


def wheel_speeds(linear: float, angular: float, radius: float, track: float) -> tuple[float, float]:
    """Forward wheel spin rates (rad/s, left and right) of a differential drive."""
    half = angular * track / 2.0
    return (linear - half) / radius, (linear + half) / radius


def nearest_ahead(truth: np.ndarray, mask: np.ndarray) -> float:
    """Nearest true range among the masked beams; inf if none hit (or none masked)."""
    ahead = truth[mask]
    return float(ahead.min()) if ahead.size else math.inf


def _condition(segment: Segment) -> tuple[str, float]:
    """The one `until` condition of a segment as (name, value)."""
    until = segment.until
    for name in ("duration", "distance", "turn", "obstacle_ahead_below", "obstacle_ahead_above"):
        value = getattr(until, name)
        if value is not None:
            return name, float(value)
    raise AssertionError("Until validates exactly one condition")  # pragma: no cover


class MotionScript:
    """Segment bookkeeping: what the robot is told to do, and when each segment ends."""

    def __init__(self, motion: Motion, *, source: str = "") -> None:
        self.segments = list(motion.segments)
        self.where = shown(source or "<scenario>")
        self.index = 0
        self.elapsed = 0.0  # s spent in the current segment
        self.t = 0.0  # s since the script started
        self._planned = [self._planned_time(i, s) for i, s in enumerate(self.segments)]

    def _planned_time(self, index: int, segment: Segment) -> float | None:
        """Exact duration of a time/distance/turn segment; None for obstacle conditions."""
        name, value = _condition(segment)
        if name == "duration":
            return value
        if name.startswith("obstacle"):
            return None
        speed = abs(segment.linear if name == "distance" else segment.angular)
        needed = value / speed if speed > 0 else math.inf
        if needed > segment.until.timeout:
            what, unit = ("linear", "m") if name == "distance" else ("angular", "rad")
            raise ConfigError(
                f"{self._field(index)}: {name} {value:g} {unit} not reached within "
                f"{segment.until.timeout:g} s ({what} {getattr(segment, what):g} {unit}/s)"
            )
        return needed

    def _field(self, index: int) -> str:
        return f"{self.where}: motion.segments[{index}].until"

    @property
    def done(self) -> bool:
        """True once every segment has ended."""
        return self.index >= len(self.segments)

    @property
    def command(self) -> tuple[float, float]:
        """(linear, angular) in force now; (0, 0) once done."""
        if self.done:
            return 0.0, 0.0
        segment = self.segments[self.index]
        return segment.linear, segment.angular

    def _next_segment(self) -> None:
        self.index += 1
        self.elapsed = 0.0

    def observe(self, ahead: float) -> None:
        """Judge obstacle conditions on a scan whose nearest range ahead is `ahead`: end each
        segment whose condition holds (at once if it held at its start); ConfigError at its
        timeout."""
        while not self.done and self._planned[self.index] is None:
            segment = self.segments[self.index]
            name, value = _condition(segment)
            reached = ahead < value if name == "obstacle_ahead_below" else ahead > value
            if reached:
                self._next_segment()
                continue
            if self.elapsed >= segment.until.timeout - EPS_TIME:
                raise ConfigError(
                    f"{self._field(self.index)}: {name} {value:g} m not reached within "
                    f"{segment.until.timeout:g} s"
                )
            break

    def advance(self, dt: float) -> list[Piece]:
        """The pieces of motion covering the next dt seconds (fewer once the script ends)."""
        pieces: list[Piece] = []
        remaining = dt
        while remaining > EPS_TIME and not self.done:
            linear, angular = self.command
            planned = self._planned[self.index]
            left = math.inf if planned is None else planned - self.elapsed
            if left <= remaining + EPS_TIME:
                take = max(0.0, min(left, remaining))
                if take > 0.0:
                    pieces.append(Piece(take, linear, angular))
                remaining -= take
                self._next_segment()
            else:
                pieces.append(Piece(remaining, linear, angular))
                self.elapsed += remaining
                remaining = 0.0
        self.t += dt
        return pieces


class RobotWorld(Protocol):
    """What the drivers need from a world (``harness.sim.world.World``)."""

    def base_pose(self) -> tuple[float, float, float]: ...

    def set_base_pose(self, x: float, y: float, yaw: float) -> None: ...

    def wheel_geometry(self, left: str, right: str) -> WheelGeometry: ...

    def set_wheel_velocities(
        self, wheels: WheelGeometry, left: float, right: float, max_torque: float
    ) -> None: ...

    def step(self, n: int = 1) -> None: ...


class KinematicDriver:
    """Sets the robot's pose exactly from the integrated script: no physics at all."""

    def __init__(self, world: RobotWorld, start: Pose) -> None:
        self.world = world
        self._pose = Pose(start.x, start.y, wrap_angle(start.yaw))
        self._t = 0.0
        world.set_base_pose(self._pose.x, self._pose.y, self._pose.yaw)

    def pose(self) -> Pose:
        """The robot's pose now."""
        return self._pose

    def run_until(self, script: MotionScript, t: float) -> None:
        """Follow the script up to simulation time t."""
        self._pose = integrate_pieces(self._pose, script.advance(t - self._t))
        self._t = t
        self.world.set_base_pose(self._pose.x, self._pose.y, self._pose.yaw)


class WheelDriver:
    """Drives the wheel motors and steps the physics at a fixed 240 Hz."""

    def __init__(self, world: RobotWorld, time_step: float) -> None:
        self.world, self.time_step = world, time_step
        self.wheels = world.wheel_geometry(*WHEEL_JOINTS)
        self._steps = 0
        self._command: tuple[float, float] | None = None
        self.drive(0.0, 0.0)
        world.step(SETTLE_STEPS)

    def pose(self) -> Pose:
        """The robot's pose now, as the physics has it."""
        return Pose(*self.world.base_pose())

    def drive(self, linear: float, angular: float) -> None:
        """Command a body velocity (m/s, rad/s) through the wheel motors; holds until changed."""
        if self._command == (linear, angular):
            return
        self._command = (linear, angular)
        wheels = self.wheels
        left, right = wheel_speeds(linear, angular, wheels.radius, wheels.track)
        self.world.set_wheel_velocities(wheels, left, right, WHEEL_MAX_TORQUE)

    def run_until(self, script: MotionScript, t: float) -> None:
        """Follow the script up to the physics step nearest simulation time t."""
        target = round(t / self.time_step)
        while self._steps < target:
            pieces = script.advance(self.time_step)
            # The command holding for most of this step (segment ends rarely fall mid-step).
            best = max(pieces, key=lambda p: p.duration) if pieces else Piece(0.0, 0.0, 0.0)
            self.drive(best.linear, best.angular)
            self.world.step()
            self._steps += 1
