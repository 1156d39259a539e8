"""Scenario files: schema, validation and lookup (pure; no pybullet here).

A scenario is a YAML file describing the world, the robot's start pose, its
LIDAR, a motion script, the fault profile and the warning threshold. Every
mistake in a file becomes one ``ConfigError`` line naming the file and the
field, e.g. ``approach.yaml: motion.segments[1].until: give exactly one of
duration, distance, turn, obstacle_ahead_below, obstacle_ahead_above``.
"""

from __future__ import annotations

import math
import os
import re
import stat
import unicodedata
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
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

from harness.errors import ConfigError
from harness.faults import FaultProfile, build_profile
from harness.lidar_spec import PRESETS, LidarSpec, preset
from harness.messages import shown
from harness.model_files import check_model_file, find_model_file, parse_xml, robot_models_dir
from harness.sim.footprint import Outline, disc, overlap, rectangle, robot_outlines
from harness.sim.geometry import cylinder_segments

SCENARIO_SUFFIXES = (".yaml", ".yml")

# What one scenario may ask for. Each bound keeps a hostile or mistaken file
# from hanging or exhausting the machine; the lab's scenarios use a small
# fraction of each (docs/scenarios.md, "Limits").
MAX_FILE_BYTES = 1 << 20  # a scenario file
MAX_YAML_DEPTH = 20  # nesting of YAML mappings and lists (aliases expanded)
MAX_YAML_NODES = 100_000  # values in the file, each alias counted at its full size
MAX_YAML_SCALAR = 4096  # characters of one YAML value
MAX_SEGMENT_SECONDS = 600.0  # one segment's duration or timeout
MAX_RUN_SECONDS = 600.0  # simulated time of a whole run, conditional segments at their timeout
MAX_SCANS = 10_000  # LIDAR revolutions of a whole run
MAX_RAYS = 10_000_000  # beams cast in a whole run (scans x samples)
MAX_CYLINDER_SIDES = 100_000  # sides of all cylinder meshes together (big radii need more)
MAX_MODELS = 100  # model (URDF/SDF) obstacles
MAX_COORDINATE = 1000.0  # m, |x| and |y| of anything placed in the world
MIN_SIZE, MAX_SIZE = 0.001, 100.0  # m, sizes of walls, boxes and cylinders
MAX_RANGE = 100.0  # m, LIDAR range_max, the threshold and obstacle conditions
MAX_PATH = 1024  # characters of a model path
START_OVERLAP = 0.005  # m the robot may overlap an obstacle where it starts (touching, rounding)
WHEEL_JOINTS = ("left_wheel_joint", "right_wheel_joint")  # what wheels mode drives


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
    if re.match(r"\s*[-+]?0[0-9]", text) and _INT_1_2.match(text.strip().lstrip("+-0") or "0"):
        return "a leading 0 is octal in YAML 1.1, not in 1.2: write 10, or 0o12 for octal"
    if _INT_1_2.match(text) or _FLOAT_1_2.match(text):
        return "quoted, so text: write it without quotes"
    return "not a number as YAML 1.2 writes one"


def _number(value: Any) -> Any:
    """A number as YAML 1.2 writes it: not true/false, not text however much it looks like one.

    An int is a number (`threshold: 1`); a float field then takes it as 1.0.
    """
    if isinstance(value, bool):  # Python's bool is an int
        raise ValueError(f"must be a number, got {str(value).lower()}")
    if isinstance(value, str):
        if _NUMERIC_TEXT.match(value):
            raise ValueError(f"must be a number, got text {value[:40]!r} ({_text_hint(value)})")
        raise ValueError("Input should be a valid number, unable to parse string as a number")
    return value


def _whole(value: Any) -> Any:
    """A whole number written as one: `360`, not `360.0`, `3.6e2` or `"360"`."""
    if isinstance(value, bool):
        raise ValueError(f"must be a whole number, got {str(value).lower()}")
    if isinstance(value, float):
        raise ValueError(f"must be a whole number, got {value!r}")
    if isinstance(value, str):
        if _NUMERIC_TEXT.match(value):
            hint = _text_hint(value)
            raise ValueError(f"must be a whole number, got text {value[:40]!r} ({hint})")
        raise ValueError("Input should be a valid integer, unable to parse string as an integer")
    return value


# Strict: pydantic converts nothing (no text to number, no 360.0 to 360); the
# validators before it say what is wrong in words.
_Number = BeforeValidator(_number)
_Whole = BeforeValidator(_whole)
Finite = Annotated[float, _Number, Field(strict=True, allow_inf_nan=False)]
Positive = Annotated[float, _Number, Field(strict=True, gt=0, allow_inf_nan=False)]
Coordinate = Annotated[
    float,
    _Number,
    Field(strict=True, ge=-MAX_COORDINATE, le=MAX_COORDINATE, allow_inf_nan=False),
]
Size = Annotated[float, _Number, Field(strict=True, ge=MIN_SIZE, le=MAX_SIZE, allow_inf_nan=False)]
Range = Annotated[float, _Number, Field(strict=True, gt=0, le=MAX_RANGE, allow_inf_nan=False)]
Angle = Annotated[
    float, _Number, Field(strict=True, ge=-2 * math.pi, le=2 * math.pi, allow_inf_nan=False)
]
Increment = Annotated[float, _Number, Field(strict=True, gt=0, le=2 * math.pi, allow_inf_nan=False)]
Rate = Annotated[float, _Number, Field(strict=True, ge=1, le=100, allow_inf_nan=False)]
Timeout = Annotated[
    float, _Number, Field(strict=True, gt=0, le=MAX_SEGMENT_SECONDS, allow_inf_nan=False)
]
Linear = Annotated[float, _Number, Field(strict=True, ge=-2.0, le=2.0, allow_inf_nan=False)]
Angular = Annotated[float, _Number, Field(strict=True, ge=-10.0, le=10.0, allow_inf_nan=False)]
Samples = Annotated[int, _Whole, Field(strict=True, ge=1, le=16383)]
Seed = Annotated[int, _Whole, Field(strict=True, ge=0, le=2**32 - 1)]
Point2 = tuple[Coordinate, Coordinate]
Text = Annotated[str, AfterValidator(_printable)]
ModelPath = Annotated[str, Field(min_length=1, max_length=MAX_PATH), AfterValidator(_printable)]


class Pose2D(_Strict):
    """A planar pose: metres and radians (yaw CCW from +x)."""

    x: Coordinate = 0.0
    y: Coordinate = 0.0
    yaw: Finite = 0.0


class RobotConfig(_Strict):
    """Which URDF to load, its LIDAR link and where it starts."""

    urdf: ModelPath = "fossbot_v2.urdf"
    lidar_link: Annotated[Text, Field(min_length=1, max_length=255)] = "lidar_scan_frame"
    start: Pose2D = Pose2D()

    @field_validator("urdf")
    @classmethod
    def _is_urdf(cls, value: str) -> str:
        if not value.endswith(".urdf"):
            raise ValueError(f"the robot must be a .urdf file, got {value[:100]!r}")
        return value


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
        base = preset(self.preset)
        return base.with_overrides(
            samples=self.samples,
            angle_min=self.angle_min,
            angle_increment=self.angle_increment,
            range_min=self.range_min,
            range_max=self.range_max,
            rate_hz=self.rate_hz,
        )


def _xy(point: Sequence[float]) -> str:
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
        return f"wall from {_xy(self.start)} to {_xy(self.end)}"


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
        return f"box at {_xy(self.position)}"


class Cylinder(_Strict):
    """An upright cylinder standing on the floor (a post, a table leg)."""

    type: Literal["cylinder"]
    position: Point2
    radius: Size
    height: Size = 0.5

    def outline(self) -> Outline:
        return disc(self.position, self.radius, self.height)

    def describe(self) -> str:
        return f"cylinder at {_xy(self.position)}, radius {self.radius:g} m"


class Model(_Strict):
    """A URDF or SDF file, relative to the scenario file or robot_models/."""

    type: Literal["model"]
    path: ModelPath
    position: tuple[Coordinate, Coordinate, Coordinate] = (0.0, 0.0, 0.0)
    yaw: Finite = 0.0

    @field_validator("path")
    @classmethod
    def _known_format(cls, value: str) -> str:
        if not value.endswith((".urdf", ".sdf")):
            raise ValueError(f"model path must end in .urdf or .sdf, got {value[:100]!r}")
        return value


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


def _first_error(err: ValidationError) -> str:
    first = err.errors(include_url=False)[0]
    msg = first["msg"].removeprefix("Value error, ")
    if first["type"] == "extra_forbidden":
        msg = "unknown key"
    elif first["type"] == "missing":
        msg = "required field is missing"
    return f"{_field_path(first['loc'])}: {shown(msg, 300)}"


def check_run_length(scenario: Scenario, faults: FaultProfile | None = None) -> None:
    """Refuse runs too long or too costly to simulate (see MAX_* above); pure arithmetic.

    A drifting scan rate (a link fault) counts at its highest rate.
    """
    segments = scenario.motion.segments
    seconds = sum(segment.worst_case_seconds() for segment in segments)
    spec = scenario.lidar_spec
    drift = faults.link.get("rate_drift") if faults is not None else None
    rate_hz = max(spec.rate_hz, drift.max_hz) if drift is not None else spec.rate_hz
    scans = math.ceil(seconds * rate_hz - 1e-9) + 1
    if seconds > MAX_RUN_SECONDS or scans > MAX_SCANS:
        waits = any(s.until.obstacle_ahead_below or s.until.obstacle_ahead_above for s in segments)
        raise ConfigError(
            f"motion: the run could last {seconds:g} s of simulated time ({scans} scans at "
            f"{rate_hz:g} Hz); at most {MAX_RUN_SECONDS:g} s and {MAX_SCANS} scans"
            + (" (segments waiting for an obstacle count at their until.timeout)" if waits else "")
        )
    if scans * spec.samples > MAX_RAYS:
        raise ConfigError(
            f"lidar: {spec.samples} samples x {scans} scans = {scans * spec.samples} beams to "
            f"cast; at most {MAX_RAYS} per run (fewer samples or a shorter run)"
        )
    sides = sum(cylinder_segments(o.radius) for o in scenario.obstacles if isinstance(o, Cylinder))
    if sides > MAX_CYLINDER_SIDES:
        raise ConfigError(
            f"obstacles: the cylinders need {sides} mesh sides in all (a bigger radius needs "
            f"more); at most {MAX_CYLINDER_SIDES} (fewer or smaller cylinders)"
        )
    models = sum(isinstance(o, Model) for o in scenario.obstacles)
    if models > MAX_MODELS:
        raise ConfigError(f"obstacles: {models} model obstacles; at most {MAX_MODELS}")


def parse_scenario(data: Any, *, source: str = "<scenario>") -> Scenario:
    """Validate already-loaded YAML data; ConfigError names the source and field.

    Checks the schema, the bounds and the cost of the run; the model files
    it names are checked by ``check_model_files`` (``load_scenario_file``
    does both).
    """
    where = shown(source)
    if not isinstance(data, dict):
        got = {type(None): "nothing (an empty file?)", list: "a list", str: "text"}.get(
            type(data), type(data).__name__
        )
        raise ConfigError(f"{where}: a scenario must be a mapping of fields, got {got}")
    if "source" in data:  # the harness's own field: where the file is, never the file's say
        raise ConfigError(f"{where}: source: unknown key")
    try:
        scenario = Scenario.model_validate({**data, "source": source})
        scenario.lidar.spec()
    except ValidationError as err:
        raise ConfigError(f"{where}: {_first_error(err)}") from None
    except ConfigError as err:
        raise ConfigError(f"{where}: lidar: {err}") from None
    except RecursionError:
        raise ConfigError(f"{where}: nested too deeply (or refers to itself)") from None
    try:
        check_run_length(scenario, build_profile(scenario.faults))
        check_lidar_fits(scenario)
    except ConfigError as err:
        raise ConfigError(f"{where}: {err}") from None
    if not scenario.name:
        scenario = scenario.model_copy(update={"name": Path(source).stem[:100]})
    return scenario


def threshold_problem(threshold: float, scenario: Scenario) -> str | None:
    """Why `threshold` cannot be judged with this scenario's LIDAR, or None.

    Beyond range_max a driver's range_max "no return" reading would need a
    warning that the oracle also lets a node leave out: no answer could be
    right. Used for the file's own threshold and for a run's override.
    """
    range_max = scenario.lidar_spec.range_max
    if threshold <= range_max:
        return None
    return (
        f"{threshold:g} m is beyond lidar.range_max ({range_max:g} m); "
        "a warning threshold must be within the LIDAR's range"
    )


def check_lidar_fits(scenario: Scenario) -> None:
    """The threshold and the obstacle conditions ask what this LIDAR can answer.

    The threshold must be within range (`threshold_problem`). An ``obstacle_ahead_*``
    condition looks at the beams within +-10 deg of straight ahead; without
    any, it could never hold (below) or would always hold (above).
    """
    from harness.sim.motion import AHEAD_HALF_WIDTH, ahead_mask  # imports this module

    spec = scenario.lidar_spec
    problem = threshold_problem(scenario.threshold, scenario)
    if problem is not None:
        raise ConfigError(f"threshold: {problem}")
    waits = [
        (index, name)
        for index, segment in enumerate(scenario.motion.segments)
        for name in ("obstacle_ahead_below", "obstacle_ahead_above")
        if getattr(segment.until, name) is not None
    ]
    if waits and not ahead_mask(spec).any():
        index, name = waits[0]
        raise ConfigError(
            f"motion.segments[{index}].until: {name} looks at the beams within "
            f"+-{math.degrees(AHEAD_HALF_WIDTH):g} deg of straight ahead, and this LIDAR "
            f"has none (beams from {spec.angle_min:.4g} to {spec.angle_max:.4g} rad)"
        )


def check_reachable(scenario: Scenario) -> None:
    """A distance or turn its segment's speed cannot cover within the timeout fails now.

    The simulation refuses these too, but only once the link (and so the
    node under test) is up; a file loaded from disk is refused before.
    """
    where = shown(scenario.source or "<scenario>")
    for index, segment in enumerate(scenario.motion.segments):
        until = segment.until
        for name, value, unit, speed, what, speed_unit in (
            ("distance", until.distance, "m", segment.linear, "linear", "m/s"),
            ("turn", until.turn, "rad", segment.angular, "angular", "rad/s"),
        ):
            needed = value / abs(speed) if value is not None and speed else math.inf
            if value is not None and needed > until.timeout:
                raise ConfigError(
                    f"{where}: motion.segments[{index}].until: {name} {value:g} {unit} not "
                    f"reached within {until.timeout:g} s ({what} {speed:g} {speed_unit})"
                )


def check_model_files(scenario: Scenario) -> Path:
    """The robot URDF and every model obstacle: found where allowed and loadable.

    The same check ``harness.sim.world.World`` runs before PyBullet sees a
    file; here it runs when the scenario file is loaded, before any node
    or board is started. Returns the robot URDF's resolved path.
    """
    folders = [scenario.base_dir, robot_models_dir()]
    where = shown(scenario.source or "<scenario>")
    refs = [("robot.urdf", scenario.robot.urdf)] + [
        (f"obstacles[{i}].path", o.path)
        for i, o in enumerate(scenario.obstacles)
        if isinstance(o, Model)
    ]
    robot = robot_path = None
    for field, ref in refs:
        what = f"{where}: {field}: cannot load {ref!r}"
        found = find_model_file(ref, folders, what=what)
        parts = check_model_file(found, what=what)
        if robot is None:
            robot, robot_path = parts, found.path
    assert robot is not None and robot_path is not None
    urdf = scenario.robot.urdf
    if scenario.robot.lidar_link not in robot.links:
        raise ConfigError(
            f"{where}: robot.lidar_link: no link named {scenario.robot.lidar_link!r} in "
            f"{urdf!r} (links: {', '.join(robot.links)})"
        )
    if scenario.motion.mode == "wheels":
        joints = dict(robot.joints)
        for name in WHEEL_JOINTS:
            if joints.get(name) not in ("revolute", "continuous"):
                kind = f"a {joints[name]} joint" if name in joints else "no such joint"
                raise ConfigError(
                    f"{where}: motion.mode: wheels mode needs a revolute joint {name!r} in "
                    f"{urdf!r} ({kind}; joints: {', '.join(joints) or 'none'})"
                )
    return robot_path


def check_start_clear(scenario: Scenario, robot_urdf: Path | None = None) -> None:
    """A robot that starts inside a wall, box or cylinder, or overlapping one, is refused.

    The robot's origin (its root link, on the floor) must lie outside each
    of them, and the collision shapes of its rigid body (read from
    `robot_urdf`, a URDF already checked by ``check_model_files``; see
    ``harness.sim.footprint``) may overlap one by at most START_OVERLAP.
    Model obstacles are not checked.
    """
    where = shown(scenario.source or "<scenario>")
    start = scenario.robot.start
    parts: list[Outline] = []
    if robot_urdf is not None:
        what = f"{where}: robot.urdf: cannot load {scenario.robot.urdf!r}"
        body = robot_outlines(parse_xml(robot_urdf, what))
        parts = [part.placed(start.x, start.y, start.yaw) for part in body]
    at = _xy((start.x, start.y))
    for index, obstacle in enumerate(scenario.obstacles):
        if isinstance(obstacle, Model):
            continue
        outline = obstacle.outline()
        if outline.contains((start.x, start.y)) > START_OVERLAP:
            raise ConfigError(
                f"{where}: robot.start: {at} is inside obstacles[{index}] ({obstacle.describe()})"
            )
        for part in parts:
            depth = overlap(part, outline)
            if depth > START_OVERLAP:
                raise ConfigError(
                    f"{where}: robot.start: the robot at {at}, yaw {start.yaw:.2f}, overlaps "
                    f"obstacles[{index}] ({obstacle.describe()}) by {depth * 1000:.1f} mm "
                    f"({shown(part.label, 100)} of {shown(scenario.robot.urdf, 100)!r})"
                )


# -- reading YAML, bounded ----------------------------------------------------


# YAML 1.2 core schema scalars. PyYAML implements YAML 1.1, which also reads
# `1_000` and `1:20` (= 80) as integers, `010` as octal 8, `0b11`, `yes`/`no`/
# `on`/`off` as booleans and `2024-01-01` as a date, but `1e-3` as text. Here
# those are text (a numeric field then refuses them), except a leading zero,
# which YAML 1.1 and 1.2 read differently (8 or 10): that is text too.
_BOOL_1_2 = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
_INT_1_2 = re.compile(r"^(?:[-+]?(?:0|[1-9][0-9]*)|0o[0-7]+|0x[0-9a-fA-F]+)$")
_FLOAT_1_2 = re.compile(
    r"^(?:[-+]?(?:\.[0-9]+|[0-9]+\.[0-9]*|[0-9]+(?=[eE]))(?:[eE][-+]?[0-9]+)?"
    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
)
_YAML = "tag:yaml.org,2002:"
_CORE_TAGS = {f"{_YAML}{kind}" for kind in ("null", "bool", "int", "float", "str", "seq", "map")}


class _ScenarioLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing what no scenario needs and a hostile file uses.

    Duplicate keys (PyYAML silently keeps the last), keys that are not text,
    nesting deeper than MAX_YAML_DEPTH (PyYAML recurses: a deep file is a
    RecursionError), and, checked on the composed document, alias "bombs":
    a few lines whose aliases expand to billions of values.
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: yaml.Node | None, index: object) -> yaml.Node | None:
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                mark = self.peek_event().start_mark
                raise yaml.composer.ComposerError(
                    None, None, f"nested deeper than {MAX_YAML_DEPTH} levels", mark
                )
            return super().compose_node(parent, index)  # type: ignore[misc]
        finally:
            self._depth -= 1

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[str, yaml.Mark] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue  # `<<: *defaults` keys may be overridden: not duplicates
            key = self.construct_object(key_node) if isinstance(key_node, yaml.ScalarNode) else None
            if not isinstance(key, str):
                shown = key_node.value if isinstance(key_node, yaml.ScalarNode) else "a collection"
                raise yaml.constructor.ConstructorError(
                    None, None, f"keys must be text, got {str(shown)[:40]!r}", key_node.start_mark
                )
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"duplicate key {key[:40]!r} (first at line {seen[key].line + 1})",
                    key_node.start_mark,
                )
            seen[key] = key_node.start_mark
        return super().construct_mapping(node, deep)


def _core_scalar(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> bool | int | float:
    """A bool, int or float as YAML 1.2 writes it, also under an explicit `!!int` etc. tag."""
    kind = node.tag.removeprefix(_YAML)
    pattern = {"bool": _BOOL_1_2, "int": _INT_1_2, "float": _FLOAT_1_2}[kind]
    text = str(loader.construct_scalar(node))
    if not pattern.match(text) and not (kind == "float" and _INT_1_2.match(text)):
        raise yaml.constructor.ConstructorError(
            None, None, f"{text[:40]!r} is not a YAML 1.2 {kind}", node.start_mark
        )
    if kind == "bool":
        return text.lower() == "true"
    if kind == "int" or (kind == "float" and _INT_1_2.match(text)):
        value = int(text, 0)
        if kind == "int":
            return value
        return float(value) if abs(value) < 2**1024 else math.copysign(math.inf, value)
    special = text.lower().lstrip("+")
    if special in (".inf", "-.inf", ".nan"):
        return float(special.replace(".", ""))
    return float(text)


# Only the YAML 1.2 core schema: implicit types as it resolves them, and no
# other tags (`!!binary`, `!!set` in an arbitrary order, `!!timestamp`, ...).
_ScenarioLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag in (f"{_YAML}null", f"{_YAML}merge")]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
for _tag, _pattern, _first in (
    ("bool", _BOOL_1_2, "tTfF"),
    ("int", _INT_1_2, "-+0123456789"),
    ("float", _FLOAT_1_2, "-+0123456789."),
):
    _ScenarioLoader.add_implicit_resolver(f"{_YAML}{_tag}", _pattern, list(_first))
_ScenarioLoader.yaml_constructors = {
    tag: construct
    for tag, construct in yaml.SafeLoader.yaml_constructors.items()
    if tag in _CORE_TAGS or tag is None
}
for _tag in ("bool", "int", "float"):
    _ScenarioLoader.add_constructor(f"{_YAML}{_tag}", _core_scalar)


def _check_expanded(root: yaml.Node) -> None:
    """Every value counted as often as aliases repeat it: bounded size, depth, no cycles."""
    sizes: dict[int, tuple[int, int]] = {}  # id(node) -> (values, depth) below and with it
    active: set[int] = set()

    def visit(node: yaml.Node) -> tuple[int, int]:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in active:
            raise yaml.composer.ComposerError(
                None, None, "an alias refers to the value it is inside", node.start_mark
            )
        if isinstance(node, yaml.ScalarNode):
            if len(node.value) > MAX_YAML_SCALAR:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"a value longer than {MAX_YAML_SCALAR} characters",
                    node.start_mark,
                )
            sizes[key] = (1, 1)
            return sizes[key]
        active.add(key)
        children: list[yaml.Node] = []
        if isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        elif isinstance(node, yaml.MappingNode):
            children = [part for pair in node.value for part in pair]
        count, depth = 1, 0
        for child in children:
            child_count, child_depth = visit(child)
            count += child_count
            depth = max(depth, child_depth)
            if count > MAX_YAML_NODES:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"more than {MAX_YAML_NODES} values once aliases are expanded",
                    node.start_mark,
                )
        active.discard(key)
        if depth + 1 > MAX_YAML_DEPTH:
            raise yaml.composer.ComposerError(
                None,
                None,
                f"nested deeper than {MAX_YAML_DEPTH} levels once aliases are expanded",
                node.start_mark,
            )
        sizes[key] = (count, depth + 1)
        return sizes[key]

    visit(root)


def load_yaml(text: str) -> Any:
    """One YAML document, safely and within bounds; yaml.YAMLError for anything refused."""
    loader = _ScenarioLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_expanded(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def _yaml_problem(err: yaml.YAMLError) -> str:
    """A PyYAML error as `YAML error at line N: problem`."""
    mark = getattr(err, "problem_mark", None)
    problem = getattr(err, "problem", None)
    if isinstance(err, yaml.reader.ReaderError):
        char = chr(err.character) if isinstance(err.character, int) else str(err.character)
        return f"YAML error: unacceptable character U+{ord(char[:1] or ' '):04X} in the file"
    where = f" at line {mark.line + 1}" if mark is not None else ""
    text = str(problem or "invalid YAML")
    context = getattr(err, "context", None)
    if context and text.startswith("but "):  # "expected a single document ..., but found ..."
        text = f"{context}, {text}"
    return f"YAML error{where}: {' '.join(text.split())}"


def _read_text(path: Path) -> str:
    """The file's text: a regular file, at most MAX_FILE_BYTES, UTF-8; never blocks on a FIFO."""
    name = shown(str(path))
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise ConfigError(f"{name}: no such scenario file") from None
    except (OSError, ValueError) as err:
        reason = getattr(err, "strerror", None) or err
        raise ConfigError(f"{name}: cannot read: {reason}") from None
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{name}: is a folder, not a scenario file")
    if not stat.S_ISREG(mode):
        raise ConfigError(f"{name}: not a regular file")
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY)
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced since the stat above
                raise ConfigError(f"{name}: not a regular file")
            with os.fdopen(os.dup(fd), "rb") as handle:
                data = handle.read(MAX_FILE_BYTES + 1)
        finally:
            os.close(fd)
    except OSError as err:
        raise ConfigError(f"{name}: cannot read: {err.strerror or err}") from None
    if len(data) > MAX_FILE_BYTES:
        raise ConfigError(f"{name}: larger than {MAX_FILE_BYTES >> 20} MiB; not a scenario file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise ConfigError(
            f"{name}: not UTF-8 text (byte 0x{data[err.start]:02x} at line {line})"
        ) from None


def load_scenario_file(path: str | Path) -> Scenario:
    """Read and validate one scenario file, and the model files it names."""
    path = Path(path)
    name = shown(str(path))
    text = _read_text(path)
    try:
        data = load_yaml(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{name}: {_yaml_problem(err)}") from None
    except RecursionError:
        raise ConfigError(f"{name}: YAML error: nested too deeply") from None
    except ValueError as err:  # e.g. an integer with more digits than Python converts
        raise ConfigError(f"{name}: YAML error: {' '.join(str(err).split())[:200]}") from None
    scenario = parse_scenario(data, source=str(path))
    check_reachable(scenario)
    check_start_clear(scenario, check_model_files(scenario))
    return scenario


def shipped_dir() -> Path:
    """Folder of the scenarios installed with the harness."""
    return Path(str(resources.files("harness.scenarios")))


def shipped_scenarios() -> list[Scenario]:
    """Every shipped scenario, sorted by name."""
    files = sorted(p for p in shipped_dir().iterdir() if p.suffix in SCENARIO_SUFFIXES)
    return sorted((load_scenario_file(p) for p in files), key=lambda s: s.name)


def _exists(path: Path) -> bool:
    """Whether anything is at `path`; a name the OS refuses (too long, a NUL) is nothing."""
    try:
        os.stat(path)
    except (OSError, ValueError):
        return False
    return True


def resolve_scenario(ref: str) -> Scenario:
    """A shipped scenario name or a path to a scenario file."""
    candidate = Path(ref)
    if candidate.suffix in SCENARIO_SUFFIXES or _exists(candidate) or "/" in ref:
        return load_scenario_file(candidate)
    for suffix in SCENARIO_SUFFIXES:
        shipped = shipped_dir() / f"{ref}{suffix}"
        if _exists(shipped):
            return load_scenario_file(shipped)
    known = ", ".join(s.name for s in shipped_scenarios())
    raise ConfigError(f"unknown scenario {ref[:100]!r} (shipped: {known}; or give a .yaml path)")
