"""Scenario files: schema, validation and lookup (pure; no pybullet here).

A scenario is a YAML file describing the world, the robot's start pose, its
LIDAR, a motion script, the fault profile and the warning threshold. Every
mistake in a file becomes one ``ConfigError`` line naming the file and the
field, e.g. ``approach.yaml: motion.segments[1].until: give exactly one of
duration, distance, turn, obstacle_ahead_below, obstacle_ahead_above``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from harness.errors import ConfigError
from harness.faults import build_profile
from harness.lidar_spec import PRESETS, LidarSpec, preset

SCENARIO_SUFFIXES = (".yaml", ".yml")
MAX_SEGMENT_SECONDS = 600.0


class _Strict(BaseModel):
    """Unknown keys are mistakes; numbers must be finite."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Point2 = tuple[Finite, Finite]


class Pose2D(_Strict):
    """A planar pose: metres and radians (yaw CCW from +x)."""

    x: Finite = 0.0
    y: Finite = 0.0
    yaw: Finite = 0.0


class RobotConfig(_Strict):
    """Which URDF to load, its LIDAR link and where it starts."""

    urdf: str = "fossbot_v2.urdf"
    lidar_link: str = "lidar_scan_frame"
    start: Pose2D = Pose2D()


class LidarConfig(_Strict):
    """A preset plus optional overrides of its fields."""

    preset: str = "gazebo"
    samples: Annotated[int, Field(ge=1, le=16383)] | None = None
    angle_min: Finite | None = None
    angle_increment: Positive | None = None
    range_min: Positive | None = None
    range_max: Positive | None = None
    rate_hz: Annotated[float, Field(gt=0, le=100, allow_inf_nan=False)] | None = None

    @field_validator("preset")
    @classmethod
    def _known_preset(cls, value: str) -> str:
        if value not in PRESETS:
            raise ValueError(f"unknown preset {value!r} (known: {', '.join(sorted(PRESETS))})")
        return value

    def spec(self) -> LidarSpec:
        base = preset(self.preset)
        return base.with_overrides(
            samples=self.samples,
            angle_min=self.angle_min,
            angle_increment=self.angle_increment,
            range_min=self.range_min,
            range_max=self.range_max,
            rate_hz=self.rate_hz,
        )


class Wall(_Strict):
    """A straight wall between two floor points."""

    type: Literal["wall"]
    start: Point2
    end: Point2
    thickness: Positive = 0.05
    height: Positive = 0.5

    @model_validator(mode="after")
    def _has_length(self) -> Wall:
        if math.dist(self.start, self.end) <= 0:
            raise ValueError("start and end must differ")
        return self


class Box(_Strict):
    """A box standing on the floor, centred at `position`, turned by `yaw`."""

    type: Literal["box"]
    position: Point2
    size: tuple[Positive, Positive, Positive]
    yaw: Finite = 0.0


class Cylinder(_Strict):
    """An upright cylinder standing on the floor (a post, a table leg)."""

    type: Literal["cylinder"]
    position: Point2
    radius: Positive
    height: Positive = 0.5


class Model(_Strict):
    """A URDF or SDF file, relative to the scenario file or robot_models/."""

    type: Literal["model"]
    path: str
    position: tuple[Finite, Finite, Finite] = (0.0, 0.0, 0.0)
    yaw: Finite = 0.0

    @field_validator("path")
    @classmethod
    def _known_format(cls, value: str) -> str:
        if not value.endswith((".urdf", ".sdf")):
            raise ValueError(f"model path must end in .urdf or .sdf, got {value!r}")
        return value


Obstacle = Annotated[Wall | Box | Cylinder | Model, Field(discriminator="type")]


class Until(_Strict):
    """When a motion segment ends: exactly one condition."""

    duration: Positive | None = None
    distance: Positive | None = None
    turn: Positive | None = None  # absolute radians turned
    obstacle_ahead_below: Positive | None = None
    obstacle_ahead_above: Positive | None = None
    timeout: Annotated[float, Field(gt=0, le=MAX_SEGMENT_SECONDS, allow_inf_nan=False)] = 60.0

    @model_validator(mode="after")
    def _exactly_one(self) -> Until:
        names = ("duration", "distance", "turn", "obstacle_ahead_below", "obstacle_ahead_above")
        given = [n for n in names if getattr(self, n) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of {', '.join(names)} (got {len(given)})")
        if self.duration is not None and self.duration > MAX_SEGMENT_SECONDS:
            raise ValueError(f"duration must be at most {MAX_SEGMENT_SECONDS:g} s")
        return self


class Segment(_Strict):
    """Constant body velocity (m/s, rad/s) until a condition holds."""

    linear: Annotated[float, Field(ge=-2.0, le=2.0, allow_inf_nan=False)] = 0.0
    angular: Annotated[float, Field(ge=-10.0, le=10.0, allow_inf_nan=False)] = 0.0
    until: Until


class Motion(_Strict):
    """A motion script: kinematic unicycle (exact) or wheel motors (physics)."""

    mode: Literal["kinematic", "wheels"] = "kinematic"
    segments: list[Segment] = Field(min_length=1, max_length=1000)


class Scenario(_Strict):
    """One scripted run of the robot through a world."""

    name: str = ""
    description: str = Field(min_length=1, max_length=200)
    robot: RobotConfig = RobotConfig()
    lidar: LidarConfig = LidarConfig()
    obstacles: list[Obstacle] = Field(default_factory=list, max_length=1000)
    motion: Motion
    faults: list[str | dict[str, Any]] = Field(default_factory=list, max_length=50)
    threshold: Positive = 0.5
    seed: Annotated[int, Field(ge=0, le=2**32 - 1)] = 0
    source: str = Field(default="", exclude=True)  # file the scenario came from

    @field_validator("description")
    @classmethod
    def _one_line(cls, value: str) -> str:
        if "\n" in value.strip():
            raise ValueError("must be one line")
        return value.strip()

    @property
    def lidar_spec(self) -> LidarSpec:
        return self.lidar.spec()

    @property
    def base_dir(self) -> Path | None:
        return Path(self.source).parent if self.source else None


def _field_path(loc: Sequence[Any]) -> str:
    """pydantic's error location as `motion.segments[1].until`."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("wall", "box", "cylinder", "model", "str", "dict[str,any]"):
            continue  # union branch tags add nothing for the reader
        else:
            out += f".{part}" if out else str(part)
    return out or "(top level)"


def _first_error(err: ValidationError) -> str:
    first = err.errors(include_url=False)[0]
    msg = first["msg"].removeprefix("Value error, ")
    if first["type"] == "extra_forbidden":
        msg = "unknown key"
    elif first["type"] == "missing":
        msg = "required field is missing"
    return f"{_field_path(first['loc'])}: {msg}"


def parse_scenario(data: Any, *, source: str = "<scenario>") -> Scenario:
    """Validate already-loaded YAML data; ConfigError names the source and field."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: a scenario must be a mapping, got {type(data).__name__}")
    try:
        scenario = Scenario.model_validate({**data, "source": source})
        scenario.lidar.spec()
    except ValidationError as err:
        raise ConfigError(f"{source}: {_first_error(err)}") from None
    except ConfigError as err:
        raise ConfigError(f"{source}: lidar: {err}") from None
    try:
        build_profile(scenario.faults)
    except ConfigError as err:
        raise ConfigError(f"{source}: {err}") from None
    if not scenario.name:
        scenario = scenario.model_copy(update={"name": Path(source).stem})
    return scenario


def load_scenario_file(path: str | Path) -> Scenario:
    """Read and validate one scenario file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such scenario file") from None
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: cannot read: {err}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or "invalid YAML"
        raise ConfigError(f"{path}: YAML error{where}: {problem}") from None
    return parse_scenario(data, source=str(path))


def shipped_dir() -> Path:
    """Folder of the scenarios installed with the harness."""
    return Path(str(resources.files("harness.scenarios")))


def shipped_scenarios() -> list[Scenario]:
    """Every shipped scenario, sorted by name."""
    files = sorted(p for p in shipped_dir().iterdir() if p.suffix in SCENARIO_SUFFIXES)
    return sorted((load_scenario_file(p) for p in files), key=lambda s: s.name)


def resolve_scenario(ref: str) -> Scenario:
    """A shipped scenario name or a path to a scenario file."""
    candidate = Path(ref)
    if candidate.suffix in SCENARIO_SUFFIXES or candidate.exists() or "/" in ref:
        return load_scenario_file(candidate)
    for suffix in SCENARIO_SUFFIXES:
        shipped = shipped_dir() / f"{ref}{suffix}"
        if shipped.is_file():
            return load_scenario_file(shipped)
    known = ", ".join(s.name for s in shipped_scenarios())
    raise ConfigError(f"unknown scenario {ref!r} (shipped: {known}; or give a .yaml path)")
