"""The scenario file's schema: what each field may hold (pydantic models, strict).

A scenario describes the world, the robot's start pose, its LIDAR, a motion
script, the fault profile and the warning threshold. Every mistake becomes
one ``ConfigError`` line naming the field (``first_error``).
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from harness.lidar.spec import PRESETS, LidarSpec, preset
from harness.ros.names import InvalidName, resolve_topic
from harness.safe_text import shown
from harness.scenario.footprint import Outline, disc, rectangle
from harness.scenario.limits import (
    MAX_COORDINATE,
    MAX_PATH,
    MAX_RANGE,
    MAX_SEGMENT_SECONDS,
    MAX_SIZE,
    MIN_SIZE,
)
from harness.scenario.yaml_loader import FLOAT_1_2, INT_1_2

WHEEL_JOINTS = ("left_wheel_joint", "right_wheel_joint")  # what wheels mode drives
# The link whose frame is the LIDAR device's own (+x its 0 degrees, +z its top);
# a URDF without it has a generic mount (harness.scenario.mount).
DEFAULT_DEVICE_LINK = "lidar_device_frame"


class _Strict(BaseModel):
    """Unknown keys are mistakes; numbers must be finite."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _printable(value: str) -> str:
    """Text shown on terminals and in reports: no control or invisible formatting characters."""
    for char in value:
        if unicodedata.category(char) in ("Cc", "Cf"):
            raise ValueError(f"must be printable text, found character U+{ord(char):04X}")
    return value


# Text that looks like a number: `"0.5"`, or YAML 1.1 forms YAML 1.2 reads as text (`1_000`).
_NUMERIC_TEXT = re.compile(r"\s*[-+]?\.?[0-9]")


def _text_hint(text: str) -> str:
    """Why `text`, which looks like a number, is text."""
    if "_" in text:
        return "YAML 1.2 numbers have no _"
    if ":" in text:
        return "YAML 1.2 reads 1:20 as text, not 80"
    if re.match(r"\s*[-+]?0[0-9]", text) and INT_1_2.match(text.strip().lstrip("+-0") or "0"):
        return "a leading 0 is octal in YAML 1.1, not in 1.2: write 10, or 0o12 for octal"
    if INT_1_2.match(text) or FLOAT_1_2.match(text):
        return "quoted, so text: write it without quotes"
    return "not a number as YAML 1.2 writes one"


def _checked(value: Any, *, whole: bool) -> Any:
    """A number as YAML 1.2 writes it: not true/false, not text however much it looks like
    one; `whole`: `360`, not `360.0` or `3.6e2`. An int is a number (a float field takes
    `threshold: 1` as 1.0)."""
    what = "a whole number" if whole else "a number"
    if isinstance(value, bool):  # Python's bool is an int
        raise ValueError(f"must be {what}, got {str(value).lower()}")
    if whole and isinstance(value, float):
        raise ValueError(f"must be a whole number, got {value!r}")
    if isinstance(value, str):
        if _NUMERIC_TEXT.match(value):
            raise ValueError(f"must be {what}, got text {value[:40]!r} ({_text_hint(value)})")
        noun = "integer" if whole else "number"
        words = f"a valid {noun}, unable to parse string as {'an' if whole else 'a'} {noun}"
        raise ValueError(f"Input should be {words}")
    return value


# Strict: pydantic converts nothing (no text to number, no 360.0 to 360); the
# validators before it say what is wrong in words.
_Whole = BeforeValidator(lambda value: _checked(value, whole=True))


def _float(**bounds: float) -> Any:
    """A finite float field within `bounds` (pydantic's gt, ge, le)."""
    number = BeforeValidator(lambda value: _checked(value, whole=False))
    return Annotated[float, number, Field(strict=True, allow_inf_nan=False, **bounds)]


Finite = _float()
Positive = _float(gt=0)
Coordinate = _float(ge=-MAX_COORDINATE, le=MAX_COORDINATE)
Size = _float(ge=MIN_SIZE, le=MAX_SIZE)
Range = _float(gt=0, le=MAX_RANGE)
Angle = _float(ge=-2 * math.pi, le=2 * math.pi)
Increment = _float(gt=0, le=2 * math.pi)
Rate = _float(ge=1, le=100)
Timeout = _float(gt=0, le=MAX_SEGMENT_SECONDS)
Linear = _float(ge=-2.0, le=2.0)
Angular = _float(ge=-10.0, le=10.0)
Samples = Annotated[int, _Whole, Field(strict=True, ge=1, le=16383)]
Seed = Annotated[int, _Whole, Field(strict=True, ge=0, le=2**32 - 1)]
Point2 = tuple[Coordinate, Coordinate]
Text = Annotated[str, AfterValidator(_printable)]
ModelPath = Annotated[str, Field(min_length=1, max_length=MAX_PATH), AfterValidator(_printable)]


def _ending(problem: str, *suffixes: str) -> AfterValidator:
    """A model path ending in one of `suffixes`; `problem` says what is wrong otherwise."""

    def check(value: str) -> str:
        if not value.endswith(suffixes):
            raise ValueError(f"{problem}, got {value[:100]!r}")
        return value

    return AfterValidator(check)


UrdfPath = Annotated[ModelPath, _ending("the robot must be a .urdf file", ".urdf")]
ModelRef = Annotated[ModelPath, _ending("model path must end in .urdf or .sdf", ".urdf", ".sdf")]


class Pose2D(_Strict):
    """A planar pose: metres and radians (yaw CCW from +x)."""

    x: Coordinate = 0.0
    y: Coordinate = 0.0
    yaw: Finite = 0.0


LinkName = Annotated[Text, Field(min_length=1, max_length=255)]


class RobotConfig(_Strict):
    """Which URDF to load, its LIDAR links and where it starts."""

    urdf: UrdfPath = "fossbot_v2.urdf"
    lidar_link: LinkName = "lidar_scan_frame"  # the scan frame: x forward, z up
    lidar_device_link: LinkName = DEFAULT_DEVICE_LINK  # where the device's zero points
    start: Pose2D = Pose2D()


class LidarConfig(_Strict):
    """A preset plus optional overrides of its fields."""

    preset: str = "gazebo"
    samples: Samples | None = None
    angle_min: Angle | None = None
    angle_increment: Increment | None = None
    range_min: Range | None = None
    range_max: Range | None = None
    rate_hz: Rate | None = None

    @field_validator("preset")
    @classmethod
    def _known_preset(cls, value: str) -> str:
        if value not in PRESETS:
            raise ValueError(f"unknown preset {value!r} (known: {', '.join(sorted(PRESETS))})")
        return value

    def spec(self) -> LidarSpec:
        """The preset with every other field as an override (None: the preset's)."""
        return preset(self.preset).with_overrides(**self.model_dump(exclude={"preset"}))


def point_text(point: Sequence[float]) -> str:
    return f"({point[0]:.2f}, {point[1]:.2f})"


class Wall(_Strict):
    """A straight wall between two floor points."""

    type: Literal["wall"]
    start: Point2
    end: Point2
    thickness: Size = 0.05
    height: Size = 0.5

    @model_validator(mode="after")
    def _has_length(self) -> Wall:
        if math.dist(self.start, self.end) <= 0:
            raise ValueError("start and end must differ")
        return self

    def outline(self) -> Outline:
        (x0, y0), (x1, y1) = self.start, self.end
        half = math.dist(self.start, self.end) / 2.0
        centre = ((x0 + x1) / 2.0, (y0 + y1) / 2.0)
        yaw = math.atan2(y1 - y0, x1 - x0)
        return rectangle(centre, half, self.thickness / 2.0, yaw, self.height)

    def describe(self) -> str:
        return f"wall from {point_text(self.start)} to {point_text(self.end)}"


class Box(_Strict):
    """A box standing on the floor, centred at `position`, turned by `yaw`."""

    type: Literal["box"]
    position: Point2
    size: tuple[Size, Size, Size]
    yaw: Finite = 0.0

    def outline(self) -> Outline:
        sx, sy, sz = self.size
        return rectangle(self.position, sx / 2.0, sy / 2.0, self.yaw, sz)

    def describe(self) -> str:
        return f"box at {point_text(self.position)}"


class Cylinder(_Strict):
    """An upright cylinder standing on the floor (a post, a table leg)."""

    type: Literal["cylinder"]
    position: Point2
    radius: Size
    height: Size = 0.5

    def outline(self) -> Outline:
        return disc(self.position, self.radius, self.height)

    def describe(self) -> str:
        return f"cylinder at {point_text(self.position)}, radius {self.radius:g} m"


class Model(_Strict):
    """A URDF or SDF file, relative to the scenario file or robot_models/."""

    type: Literal["model"]
    path: ModelRef
    position: tuple[Coordinate, Coordinate, Coordinate] = (0.0, 0.0, 0.0)
    yaw: Finite = 0.0


Obstacle = Annotated[Wall | Box | Cylinder | Model, Field(discriminator="type")]


class Until(_Strict):
    """When a motion segment ends: exactly one condition."""

    duration: Positive | None = None
    distance: Positive | None = None
    turn: Positive | None = None  # absolute radians turned
    obstacle_ahead_below: Range | None = None
    obstacle_ahead_above: Range | None = None
    timeout: Timeout = 60.0

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

    linear: Linear = 0.0
    angular: Angular = 0.0
    until: Until

    def worst_case_seconds(self) -> float:
        """Longest this segment can run: its duration, its exact time, or its timeout."""
        until = self.until
        if until.duration is not None:
            return until.duration
        for value, speed in ((until.distance, self.linear), (until.turn, self.angular)):
            if value is not None and speed != 0:
                return min(value / abs(speed), until.timeout)
        return until.timeout  # obstacle conditions; unreachable ones fail before they run


class Motion(_Strict):
    """A motion script: kinematic unicycle (exact) or wheel motors (physics)."""

    mode: Literal["kinematic", "wheels"] = "kinematic"
    segments: list[Segment] = Field(min_length=1, max_length=1000)


class NodeTopics(_Strict):
    """The topics a scenario asks the node to use, through its topic parameters: a lab
    with a second robot, or a namespaced one, names them so. Unset ones keep the run's."""

    scan: str | None = None
    status: str | None = None
    warning: str | None = None

    @field_validator("scan", "status", "warning")
    @classmethod
    def _topic(cls, value: str | None) -> str | None:
        if value is None:
            return None
        try:
            return resolve_topic(value)
        except InvalidName as err:
            raise ValueError(str(err)) from None

    @model_validator(mode="after")
    def _distinct(self) -> NodeTopics:
        named = [t for t in (self.scan, self.status, self.warning) if t is not None]
        if len(set(named)) != len(named):
            raise ValueError("scan, status and warning must be different topics")
        return self


class Scenario(_Strict):
    """One scripted run of the robot through a world."""

    name: Annotated[Text, Field(max_length=100)] = ""
    description: Annotated[str, Field(min_length=1, max_length=200)]
    robot: RobotConfig = RobotConfig()
    lidar: LidarConfig = LidarConfig()
    obstacles: list[Obstacle] = Field(default_factory=list, max_length=1000)
    motion: Motion
    faults: list[Annotated[str, Field(max_length=100)] | dict[str, Any]] = Field(
        default_factory=list, max_length=50
    )
    threshold: Range = 0.5
    node_topics: NodeTopics | None = None  # ros2 link: the node's topics, set by parameter
    # "required": the node must publish warning False whenever nothing is within the
    # threshold; "optional" (the lab's rule): a Bool only when close is fine too.
    warning_when_clear: Literal["optional", "required"] = "optional"
    seed: Seed = 0
    source: str = Field(default="", exclude=True)  # file the scenario came from

    @field_validator("description")
    @classmethod
    def _one_line(cls, value: str) -> str:
        if not value.strip():
            raise ValueError("must not be blank")
        if "\n" in value.strip():
            raise ValueError("must be one line")
        return _printable(value.strip())

    @field_validator("name")
    @classmethod
    def _name_one_line(cls, value: str) -> str:
        if value != value.strip():
            raise ValueError("must not start or end with spaces")
        return value

    @property
    def lidar_spec(self) -> LidarSpec:
        return self.lidar.spec()

    @property
    def base_dir(self) -> Path | None:
        return Path(self.source).parent if self.source else None


_UNION_TAGS = ("wall", "box", "cylinder", "model", "str", "constrained-str", "dict[str,any]")


def _field_path(loc: Sequence[Any]) -> str:
    """pydantic's error location as `motion.segments[1].until`."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in _UNION_TAGS or str(part).startswith("function-"):
            continue  # union branch tags add nothing for the reader
        else:
            text = shown(str(part), 40) if str(part).isprintable() else repr(str(part))[:40]
            out += f".{text}" if out else text
    return out or "(top level)"


def first_error(err: ValidationError) -> str:
    first = err.errors(include_url=False)[0]
    msg = first["msg"].removeprefix("Value error, ")
    if first["type"] == "extra_forbidden":
        msg = "unknown key"
    elif first["type"] == "missing":
        msg = "required field is missing"
    return f"{_field_path(first['loc'])}: {shown(msg, 300)}"
