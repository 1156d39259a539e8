"""What a /cmd_vel command becomes on the FOSSBot's wheels (pure).

Sideways and vertical parts of a Twist are ignored, as the lab's Gazebo
plugin does; a robot that stops hearing commands stops, as its teleop expects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

TOP_SPEED = 0.4  # m/s at the wheel rim: a sensible top speed for the v2's small gear motors
COMMAND_TIMEOUT_S = 0.5  # no /cmd_vel for this long: the robot stops


@dataclass(frozen=True)
class DriveLimits:
    """The robot's wheels: track (m), each wheel's top rim speed (m/s)."""

    track: float
    top_speed: float = TOP_SPEED

    @property
    def top_turn(self) -> float:
        """rad/s when turning on the spot at top wheel speed."""
        return 2.0 * self.top_speed / self.track

    def limit(self, linear: float, angular: float) -> tuple[float, float]:
        """The body velocity (m/s, rad/s) the wheels can give: beyond a wheel's top speed
        scaled down whole, so the robot drives the arc asked for, slower; NaN counts as 0."""
        linear = linear if math.isfinite(linear) else 0.0
        angular = angular if math.isfinite(angular) else 0.0
        left = linear - angular * self.track / 2.0
        right = linear + angular * self.track / 2.0
        fastest = max(abs(left), abs(right))
        if fastest <= self.top_speed:
            return linear, angular
        scale = self.top_speed / fastest
        return linear * scale, angular * scale


class CommandWatchdog:
    """The command in force: the last one heard, or a stop once they stop coming."""

    def __init__(self, timeout: float = COMMAND_TIMEOUT_S) -> None:
        self.timeout = timeout
        self._command = (0.0, 0.0)
        self._heard_at: float | None = None

    def heard(self, linear: float, angular: float, now: float) -> None:
        self._command = (linear, angular)
        self._heard_at = now

    def command(self, now: float) -> tuple[float, float]:
        """(m/s, rad/s) in force at `now` (the same clock as `heard`)."""
        if self._heard_at is None or now - self._heard_at > self.timeout:
            return 0.0, 0.0
        return self._command
