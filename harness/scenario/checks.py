"""Checks across fields and files that the schema alone cannot make (pure).

Is the run too long to simulate, can this LIDAR answer the threshold and
the obstacle conditions, can the robot reach what the script asks, do the
model files load, does the robot start clear of every obstacle.
"""

from __future__ import annotations

import math
from pathlib import Path

from harness.errors import ConfigError
from harness.faults.sensor import FaultProfile
from harness.safe_text import shown
from harness.scenario.ahead import AHEAD_HALF_WIDTH, ahead_mask
from harness.scenario.footprint import Outline, overlap, robot_outlines
from harness.scenario.geometry import cylinder_segments
from harness.scenario.limits import (
    MAX_CYLINDER_SIDES,
    MAX_MODELS,
    MAX_RAYS,
    MAX_RUN_SECONDS,
    MAX_SCANS,
    START_OVERLAP,
)
from harness.scenario.model_files import (
    check_model_file,
    find_model_file,
    parse_xml,
    robot_models_dir,
)
from harness.scenario.mount import lidar_mount
from harness.scenario.schema import WHEEL_JOINTS, Cylinder, Model, Scenario, point_text


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

    An ``obstacle_ahead_*`` condition looks at the beams within +-10 deg ahead;
    without any it could never hold (below) or would always hold (above).
    """
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

    ``World`` runs the same check before PyBullet sees a file; here it runs at
    load, before any node or board starts, with the robot's LIDAR mount. Returns
    the robot URDF's resolved path.
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
    lidar_mount(scenario, robot_path)
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

    Its origin must lie outside each, and its rigid body's collision shapes
    (``footprint``, from the checked `robot_urdf`) may overlap one by at most
    START_OVERLAP. Model obstacles are not checked.
    """
    where = shown(scenario.source or "<scenario>")
    start = scenario.robot.start
    parts: list[Outline] = []
    if robot_urdf is not None:
        what = f"{where}: robot.urdf: cannot load {scenario.robot.urdf!r}"
        body = robot_outlines(parse_xml(robot_urdf, what))
        parts = [part.placed(start.x, start.y, start.yaw) for part in body]
    at = point_text((start.x, start.y))
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
