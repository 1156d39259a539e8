"""How a run option's value is read: text from a command line or an ini file, or a value
already typed (hil.run's keywords, a grading file's YAML). Each reader raises
`OptionError` naming the option as ``{key}``, so every caller words it its own way."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from harness.errors import OptionError
from harness.option_names import escaped

Reader = Callable[[object], Any]
MAX_WAIT_S = 86400.0  # the OS's timed waits overflow past 24 days; no wait needs a day
SEED_LIMIT = 2**32


def literal(value: object, limit: int = 40) -> str:
    """`value` as a message shows it (repr, cut), braces doubled for the template."""
    return escaped(repr(value[:limit] if isinstance(value, str) else value)[: limit + 20])


def _number(value: object, kind: type) -> float | int | None:
    """`value` read as `kind` (from text, or as given); None when it is not one."""
    if isinstance(value, bool):
        return None
    if isinstance(value, str):
        try:
            return kind(value)
        except ValueError:
            return None
    if kind is int:
        return value if isinstance(value, int) else None
    return float(value) if isinstance(value, (int, float)) else None


def positive(key: str, maximum: float = math.inf) -> Reader:
    """A finite number above zero (and at most `maximum`)."""

    def read(value: object) -> float:
        number = _number(value, float)
        if number is None:
            raise OptionError(key, f"{{{key}}} must be a number, got {literal(value)}")
        if not math.isfinite(number) or number <= 0:
            raise OptionError(key, f"{{{key}}} must be a positive number, got {literal(value)}")
        if number > maximum:
            raise OptionError(key, f"{{{key}}} must be at most {maximum:g}, got {literal(value)}")
        return float(number)

    return read


def duration(key: str) -> Reader:
    """Seconds to wait for something: positive, at most a day."""
    return positive(key, MAX_WAIT_S)


def whole(key: str, low: int, high: int | None = None) -> Reader:
    """A whole number from `low` (to `high`)."""
    bounds = f">= {low}" if high is None else f"{low}..{high}"

    def read(value: object) -> int:
        number = _number(value, int)
        if number is None or number < low or (high is not None and number > high):
            got = literal(value)
            raise OptionError(key, f"{{{key}}} must be a whole number {bounds}, got {got}")
        return int(number)

    return read


def seed(value: object) -> int:
    """A seed for numpy's generators: a whole number in 0..2**32-1."""
    number = _number(value, int)
    if number is None:
        raise OptionError("seed", f"{{seed}} must be a whole number, got {literal(value)}")
    if not 0 <= number < SEED_LIMIT:
        raise OptionError(
            "seed", f"{{seed}} must be a whole number in 0..2**32-1, got {literal(value)}"
        )
    return int(number)


def choice(key: str, choices: Sequence[str]) -> Reader:
    """One of `choices`."""

    def read(value: object) -> str:
        if not isinstance(value, str) or value not in choices:
            known = " or ".join(choices)
            raise OptionError(key, f"give {known}, got {literal(value)}")
        return value

    return read


def text(key: str) -> Reader:
    """A value that must not be empty: '' would silently mean "not given"."""

    def read(value: object) -> str:
        if not isinstance(value, str):
            raise OptionError(key, f"{{{key}}} must be text, got {literal(value)}")
        if not value.strip():
            raise OptionError(key, "must not be empty")
        return value

    return read


def parameter(value: object) -> str:
    """NAME:=VALUE that ROS 2 itself can parse (harness.ros.names has the rules)."""
    from harness.ros.names import InvalidName, check_parameter_rule

    if not isinstance(value, str):
        raise OptionError("params", f"{{params}} must be NAME:=VALUE, got {literal(value)}")
    try:
        return check_parameter_rule(value)
    except InvalidName as err:
        raise OptionError("params", escaped(str(err))) from None


def link(value: object) -> str:
    """A link the table of links knows."""
    from harness.links.kinds import link_names

    if not isinstance(value, str) or value not in link_names():
        known = ", ".join(link_names())
        raise OptionError("link", f"unknown link {literal(value)} (known: {known})")
    return value


def lidar_mount(value: object) -> Any:
    """How the device sits on the robot (harness.lidar.mount); a parsed mount stays one."""
    from harness.lidar.mount import LidarMount, parse_mount

    if isinstance(value, LidarMount) or value is None:
        return value
    return parse_mount(str(value))  # an OptionError naming {lidar_mount}
