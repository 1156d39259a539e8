"""Scenario files: the shipped ones load, and every kind of mistake is one clear line."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.scenario.files import load_scenario_file, resolve_scenario, shipped_scenarios

GOOD = """\
description: A wall ahead.
obstacles:
  - type: wall
    start: [2.0, -1.0]
    end: [2.0, 1.0]
motion:
  segments:
    - linear: 0.2
      until: {duration: 1.0}
"""


def write(tmp_path: Path, text: str, name: str = "mine.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def changed(change: str) -> str:
    """GOOD with `change` appended, replacing a top-level key GOOD already has (no duplicates)."""
    key = change.split(":", 1)[0]
    kept = [line for line in GOOD.splitlines(keepends=True) if not line.startswith(f"{key}:")]
    return "".join(kept) + change


def test_shipped_scenarios_load_with_unique_names() -> None:
    """Every shipped file validates, and names are unique."""
    scenarios = shipped_scenarios()
    names = [s.name for s in scenarios]
    assert len(names) == len(set(names))
    for required in ("approach_wall", "drive_past_10m", "out_of_range"):
        assert required in names


def test_name_defaults_to_file_stem(tmp_path: Path) -> None:
    """A file without `name:` is called after its file."""
    scenario = load_scenario_file(write(tmp_path, GOOD))
    assert scenario.name == "mine"
    assert scenario.threshold == 0.5 and scenario.lidar.preset == "gazebo"


def test_resolve_by_name_and_by_path(tmp_path: Path) -> None:
    """A shipped name and a file path both resolve."""
    assert resolve_scenario("approach_wall").name == "approach_wall"
    assert resolve_scenario(str(write(tmp_path, GOOD))).name == "mine"


@pytest.mark.parametrize(
    ("change", "field", "reason"),
    [
        ("threshold: 0.5\nsped: 3\n", "sped", "unknown key"),
        ("threshold: abc\n", "threshold", "valid number"),
        ("threshold: -1\n", "threshold", "greater than 0"),
        ("threshold: .nan\n", "threshold", "finite"),
        ("seed: -3\n", "seed", "greater than or equal to 0"),
        ("lidar: {preset: velodyne}\n", "lidar.preset", "unknown preset 'velodyne'"),
        ("lidar: {samples: 0}\n", "lidar.samples", "greater than or equal to 1"),
        ("lidar: {range_min: 5, range_max: 1}\n", "lidar", "range_min < range_max"),
        ("robot: {start: {x: 1, z: 2}}\n", "robot.start.z", "unknown key"),
        ("description: null\n", "description", "valid string"),
    ],
)
def test_each_mistake_names_file_and_field(
    tmp_path: Path, change: str, field: str, reason: str
) -> None:
    """A wrong value is reported as `file: field: reason`."""
    path = write(tmp_path, changed(change))
    with pytest.raises(ConfigError, match=rf"^{path}: {field}: .*{reason}"):
        load_scenario_file(path)


def test_missing_required_field(tmp_path: Path) -> None:
    """A scenario needs a motion script."""
    path = write(tmp_path, "description: nothing moves\n")
    with pytest.raises(ConfigError, match=rf"^{path}: motion: required field is missing$"):
        load_scenario_file(path)


@pytest.mark.parametrize(
    ("until", "reason"),
    [
        ("{duration: 1, distance: 2}", "give exactly one of"),
        ("{}", "give exactly one of"),
        ("{duration: -1}", "greater than 0"),
        ("{duration: 1e9}", "at most 600 s"),
        ("{duration: .inf}", "finite"),
    ],
)
def test_bad_until_condition(tmp_path: Path, until: str, reason: str) -> None:
    """Segment end conditions: exactly one, positive and bounded."""
    text = GOOD.replace("{duration: 1.0}", until)
    path = write(tmp_path, text)
    with pytest.raises(ConfigError, match=rf"^{path}: motion.segments\[0\].until.*: .*{reason}"):
        load_scenario_file(path)


def test_unknown_obstacle_type(tmp_path: Path) -> None:
    """The obstacle list says which item and what types exist."""
    path = write(tmp_path, GOOD.replace("type: wall", "type: tree"))
    with pytest.raises(ConfigError, match=rf"^{path}: obstacles\[0\].*'wall', 'box', 'cylinder'"):
        load_scenario_file(path)


def test_zero_length_wall(tmp_path: Path) -> None:
    """A wall whose ends coincide is refused."""
    path = write(tmp_path, GOOD.replace("end: [2.0, 1.0]", "end: [2.0, -1.0]"))
    with pytest.raises(ConfigError, match=rf"^{path}: obstacles\[0\]: start and end must differ"):
        load_scenario_file(path)


def test_yaml_syntax_error_gives_line(tmp_path: Path) -> None:
    """Broken YAML reports the line."""
    path = write(tmp_path, GOOD + "threshold: [1, 2\n")
    with pytest.raises(ConfigError, match=rf"^{path}: YAML error at line \d+"):
        load_scenario_file(path)


@pytest.mark.parametrize("text", ["- a\n- b\n", "just text\n", ""])
def test_not_a_mapping(tmp_path: Path, text: str) -> None:
    """A list, a string or an empty file is not a scenario."""
    path = write(tmp_path, text)
    with pytest.raises(ConfigError, match=rf"^{path}: a scenario must be a mapping"):
        load_scenario_file(path)


def test_missing_file_and_unknown_name(tmp_path: Path) -> None:
    """Paths that do not exist and names that are not shipped."""
    with pytest.raises(ConfigError, match="no such scenario file"):
        resolve_scenario(str(tmp_path / "nope.yaml"))
    with pytest.raises(
        ConfigError, match=r"unknown scenario 'aproach_wall' \(shipped: .*approach_wall"
    ):
        resolve_scenario("aproach_wall")


def test_messages_are_one_line(tmp_path: Path) -> None:
    """Every validation message fits on one line."""
    for change in ("sped: 3\n", "threshold: abc\n", "obstacles: 5\n", "motion: {segments: []}\n"):
        path = write(tmp_path, GOOD + change)
        with pytest.raises(ConfigError) as info:
            load_scenario_file(path)
        assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("segment", "reason"),
    [
        (
            "{angular: 1.0, until: {distance: 1.0}}",
            r"distance 1 m not reached within 60 s \(linear 0",
        ),
        (
            "{linear: 0.1, until: {distance: 10, timeout: 5}}",
            r"distance 10 m not reached within 5 s",
        ),
        ("{angular: 0.5, until: {turn: 6, timeout: 2}}", r"turn 6 rad not reached within 2 s"),
    ],
)
def test_unreachable_segment_is_refused_at_load(tmp_path: Path, segment: str, reason: str) -> None:
    """A distance or turn the speed cannot cover is refused when the file loads."""
    path = write(tmp_path, f"description: x\nmotion:\n  segments:\n    - {segment}\n")
    with pytest.raises(ConfigError, match=rf"^{path}: motion\.segments\[0\]\.until: {reason}"):
        load_scenario_file(path)


# -- issue 12 item 9: files that cannot be what they say ------------------------

STILL = "description: x\nmotion:\n  segments:\n    - until: {duration: 0.5}\n"


@pytest.mark.parametrize(
    ("obstacle", "shown"),
    [
        ("{type: wall, start: [0, -1], end: [0, 1], thickness: 0.2}", "wall from (0.00, -1.00)"),
        ("{type: box, position: [0.3, 0.2], size: [1, 1, 0.4], yaw: 0.3}", "box at (0.30, 0.20)"),
        ("{type: cylinder, position: [1.0, 1.0], radius: 1.5}", "cylinder at (1.00, 1.00)"),
    ],
)
def test_robot_starting_inside_an_obstacle_is_refused(
    tmp_path: Path, obstacle: str, shown: str
) -> None:
    """The robot's origin inside a wall, box or cylinder: one line naming the obstacle."""
    obstacles = f"obstacles:\n  - {{type: wall, start: [5, -1], end: [5, 1]}}\n  - {obstacle}\n"
    path = write(tmp_path, STILL + obstacles)
    with pytest.raises(ConfigError) as info:
        load_scenario_file(path)
    assert str(info.value).startswith(
        f"{path}: robot.start: (0.00, 0.00) is inside obstacles[1] ({shown}"
    ), str(info.value)


@pytest.mark.parametrize(
    ("start", "obstacle", "part"),
    [
        # The chassis box spans x -0.12..0.06, y +-0.075 (robot_models/README.md).
        ("{x: 0, y: 0}", "{type: wall, start: [0.1, -1], end: [0.1, 1], thickness: 0.1}", "box"),
        ("{x: 0, y: 0}", "{type: cylinder, position: [-0.2, 0.0], radius: 0.1}", "box"),
        (
            "{x: 0, y: 0, yaw: 3.14159}",
            "{type: box, position: [0.16, 0], size: [0.1, 1, 1]}",
            "box",
        ),
        # The caster sphere (radius 0.015 at x = -0.095) under a low box.
        ("{x: 0, y: 0}", "{type: box, position: [-0.095, 0], size: [0.02, 0.02, 0.02]}", "sphere"),
    ],
)
def test_robot_overlapping_an_obstacle_is_refused(
    tmp_path: Path, start: str, obstacle: str, part: str
) -> None:
    """The robot's body, not just its origin, must be clear of walls, boxes and cylinders."""
    path = write(tmp_path, STILL + f"robot: {{start: {start}}}\nobstacles:\n  - {obstacle}\n")
    with pytest.raises(
        ConfigError,
        match=rf"^{path}: robot\.start: the robot at \(0\.00, 0\.00\), yaw .* overlaps "
        rf"obstacles\[0\] \(.*\) by \d+\.\d mm "
        rf"\(link '\w+' collision {part} of 'fossbot_v2.urdf'\)$",
    ):
        load_scenario_file(path)


@pytest.mark.parametrize(
    "obstacle",
    [
        # touching the chassis front (x = 0.06) and within the 5 mm tolerance
        "{type: wall, start: [0.085, -1], end: [0.085, 1], thickness: 0.05}",
        "{type: wall, start: [0.083, -1], end: [0.083, 1], thickness: 0.05}",
        # under the chassis (its bottom is 0.025 m up), between caster and wheels
        "{type: box, position: [0.03, 0], size: [0.04, 0.1, 0.02]}",
        # beside the chassis, inside the wheel: wheels turn, so they are not counted
        # (as out_of_range.yaml's post at (-0.016, 0.10))
        "{type: cylinder, position: [0.0, 0.09], radius: 0.01}",
        # diagonal to the chassis corner (0.06, 0.075), 6.6 mm away: a corner is not an edge
        "{type: cylinder, position: [0.10, 0.115], radius: 0.05}",
        # models are not checked (docs/scenarios.md)
        "{type: model, path: fossbot_v2.urdf}",
    ],
)
def test_robot_next_to_an_obstacle_loads(tmp_path: Path, obstacle: str) -> None:
    """Touching, tolerance, height and moving parts: what the start check leaves alone."""
    load_scenario_file(write(tmp_path, STILL + f"obstacles:\n  - {obstacle}\n"))


def test_robot_footprint_comes_from_its_urdf(tmp_path: Path) -> None:
    """Another URDF's body (a rotated box on a fixed joint) is what is checked."""
    (tmp_path / "wide.urdf").write_text(
        '<?xml version="1.0"?><robot name="wide">'
        '<link name="base"/><link name="deck"><collision><origin xyz="0 0 0.1" rpy="0 0 0.5"/>'
        '<geometry><box size="1.0 0.2 0.1"/></geometry></collision></link>'
        '<link name="laser"/>'
        '<joint name="a" type="fixed"><parent link="base"/><child link="deck"/></joint>'
        '<joint name="b" type="fixed"><parent link="deck"/><child link="laser"/></joint>'
        "</robot>"
    )
    robot = "robot: {urdf: wide.urdf, lidar_link: laser}\n"
    # 0.5 rad to the left, the deck reaches (0.44, 0.24); the post at (0.4, 0.3) is hit.
    hit = write(
        tmp_path,
        STILL + robot + "obstacles: [{type: cylinder, position: [0.4, 0.3], radius: 0.05}]\n",
    )
    with pytest.raises(
        ConfigError, match=r"overlaps obstacles\[0\].*link 'deck' collision box of 'wide.urdf'"
    ):
        load_scenario_file(hit)
    clear = write(
        tmp_path,
        STILL + robot + "obstacles: [{type: cylinder, position: [0.4, -0.3], radius: 0.05}]\n",
        "clear.yaml",
    )
    load_scenario_file(clear)


@pytest.mark.parametrize(
    ("change", "field", "message"),
    [
        ('threshold: "0.5"\n', "threshold", "must be a number, got text '0.5' (quoted"),
        ("threshold: 1_0.5\n", "threshold", "must be a number, got text '1_0.5'"),
        (
            "seed: 1_0\n",
            "seed",
            "must be a whole number, got text '1_0' (YAML 1.2 numbers have no _)",
        ),
        ("seed: 1:20\n", "seed", "must be a whole number, got text '1:20'"),
        ("seed: 010\n", "seed", "must be a whole number, got text '010' (a leading 0 is octal"),
        ("seed: 0b11\n", "seed", "must be a whole number, got text '0b11'"),
        ("seed: '7'\n", "seed", "must be a whole number, got text '7' (quoted"),
        ("seed: 7.0\n", "seed", "must be a whole number, got 7.0"),
        ("lidar: {samples: 360.0}\n", "lidar.samples", "must be a whole number, got 360.0"),
        ("lidar: {samples: 3.6e2}\n", "lidar.samples", "must be a whole number, got 360.0"),
        ("lidar: {samples: true}\n", "lidar.samples", "must be a whole number, got true"),
        ("lidar: {range_max: '8'}\n", "lidar.range_max", "must be a number, got text '8'"),
        ("robot: {start: {x: '0.1'}}\n", "robot.start.x", "must be a number, got text '0.1'"),
        ("threshold: !!str 0.5\n", "threshold", "must be a number, got text '0.5'"),
    ],
)
def test_numbers_are_strict(tmp_path: Path, change: str, field: str, message: str) -> None:
    """Nothing is coerced: text, YAML 1.1 forms and floats for counts are refused by field."""
    path = write(tmp_path, changed(change))
    with pytest.raises(ConfigError) as info:
        load_scenario_file(path)
    assert str(info.value).startswith(f"{path}: {field}: {message}"), str(info.value)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ("seed: !!int 1_0\n", "'1_0' is not a YAML 1.2 int"),
        ("name: !!bool yes\n", "'yes' is not a YAML 1.2 bool"),
        ("faults: !!set {noisy: null}\n", "a constructor for the tag 'tag:yaml.org,2002:set'"),
        ("description: !!binary aGVsbG8=\n", "tag 'tag:yaml.org,2002:binary'"),
        ("description: !!timestamp 2024-01-01\n", "tag 'tag:yaml.org,2002:timestamp'"),
    ],
)
def test_only_yaml_1_2_core_types(tmp_path: Path, change: str, reason: str) -> None:
    """Explicit tags beyond YAML 1.2's core schema (a !!set has no order) are refused."""
    path = write(tmp_path, changed(change))
    with pytest.raises(ConfigError, match=rf"^{path}: YAML error at line \d+: .*{reason}"):
        load_scenario_file(path)


@pytest.mark.parametrize(
    ("change", "attribute", "value"),
    [
        ("threshold: 1\n", "threshold", 1.0),  # an int where a float is meant is fine
        ("threshold: 1e-1\n", "threshold", 0.1),
        ("seed: 0x10\n", "seed", 16),  # YAML 1.2 core hex and octal
        ("seed: 0o17\n", "seed", 15),
        ("seed: +5\n", "seed", 5),
        ("name: no\n", "name", "no"),  # YAML 1.1's booleans are text in YAML 1.2
        ("name: on\n", "name", "on"),
        ("description: 2024-01-01\n", "description", "2024-01-01"),  # and so are dates
    ],
)
def test_yaml_1_2_numbers_and_text_load(
    tmp_path: Path, change: str, attribute: str, value: object
) -> None:
    """What YAML 1.2 reads as a number is one; what it reads as text stays text."""
    scenario = load_scenario_file(write(tmp_path, changed(change)))
    got = getattr(scenario, attribute)
    assert got == value and type(got) is type(value)


@pytest.mark.parametrize(
    ("lidar", "reason"),
    [
        (
            "{samples: 720, angle_increment: 0.0175}",
            r"lidar: the beams span \(samples - 1\) x angle_increment = 719 x 0\.0175 = 12\.5825 "
            r"rad, more than one turn",
        ),
        ("{preset: rplidar_a1, samples: 362}", r"lidar: the beams span .* = 361 x 0\.0174533"),
        (
            "{preset: gazebo, angle_min: 3.2}",
            r"lidar: the last beam's angle, angle_min \+ \(samples - 1\) x angle_increment = "
            r"3\.2 \+ 6\.28319 = 9\.48319 rad, is beyond 2 pi",
        ),
    ],
)
def test_scan_wider_than_one_turn_is_refused(tmp_path: Path, lidar: str, reason: str) -> None:
    """At most one revolution of beams, every beam angle within +-2 pi."""
    path = write(tmp_path, changed(f"lidar: {lidar}\n"))
    with pytest.raises(ConfigError, match=rf"^{path}: {reason}"):
        load_scenario_file(path)


@pytest.mark.parametrize(
    "lidar",
    [
        "{preset: gazebo}",  # closed layout: (360 - 1) x 2 pi / 359 = 2 pi, first beam = last
        "{preset: rplidar_a1, samples: 361}",  # 0 .. 2 pi inclusive
        "{preset: ld19}",
        "{preset: gazebo, samples: 360, angle_increment: 0.01750192}",  # float32 rounding
        "{preset: rplidar_a1, angle_min: -6.28}",
    ],
)
def test_scans_of_one_turn_load(tmp_path: Path, lidar: str) -> None:
    """The presets, a full closed turn and float rounding pass."""
    load_scenario_file(write(tmp_path, changed(f"lidar: {lidar}\n")))


def test_threshold_beyond_range_max_is_refused(tmp_path: Path) -> None:
    """A warning due for every return, even a driver's range_max 'no return', cannot be judged."""
    path = write(tmp_path, changed("lidar: {range_max: 4.0}\nthreshold: 5\n"))
    with pytest.raises(
        ConfigError, match=rf"^{path}: threshold: 5 m is beyond lidar\.range_max \(4 m\)"
    ):
        load_scenario_file(path)
    load_scenario_file(
        write(tmp_path, changed("lidar: {range_max: 4.0}\nthreshold: 4\n"), "ok.yaml")
    )


@pytest.mark.parametrize("condition", ["obstacle_ahead_below", "obstacle_ahead_above"])
def test_obstacle_condition_without_a_beam_ahead_is_refused(tmp_path: Path, condition: str) -> None:
    """A LIDAR with no beam within +-10 deg of straight ahead cannot judge `obstacle_ahead_*`."""
    text = (
        "description: x\nlidar: {preset: rplidar_a1, angle_min: 1.0, samples: 90}\n"
        f"motion:\n  segments:\n    - until: {{{condition}: 0.5}}\n"
    )
    path = write(tmp_path, text)
    with pytest.raises(
        ConfigError,
        match=rf"^{path}: motion\.segments\[0\]\.until: {condition} looks at the beams within "
        r"\+-10 deg of straight ahead, and this LIDAR has none \(beams from 1 to 2\.553 rad\)$",
    ):
        load_scenario_file(path)


def test_the_warning_rule_is_a_field_and_settings_override_it(tmp_path: Path) -> None:
    """`warning_when_clear: required` in a file makes the oracle strict; a run's setting wins."""
    from harness.runner.settings import RunSettings, warning_rule

    strict = load_scenario_file(write(tmp_path, changed("warning_when_clear: required\n")))
    assert warning_rule(strict, RunSettings()) == "required"
    assert warning_rule(strict, RunSettings(warning_when_clear="optional")) == "optional"
    assert resolve_scenario("approach_wall").warning_when_clear == "optional"
    path = write(tmp_path, changed("warning_when_clear: always\n"), "bad.yaml")
    with pytest.raises(ConfigError, match=rf"^{path}: warning_when_clear: .*'optional'"):
        load_scenario_file(path)


# -- the LIDAR's mount: read from the robot model ---------------------------------


def mount_urdf(tmp_path: Path, device_joint: str, *, scan_rpy: str = "0 0 0") -> None:
    """`bot.urdf`: base -> laser (the scan link, at `scan_rpy`) and a device link `dev`."""
    (tmp_path / "bot.urdf").write_text(
        '<?xml version="1.0"?><robot name="bot">'
        '<link name="base"/><link name="laser"/><link name="dev"/>'
        '<joint name="scan" type="fixed"><parent link="base"/><child link="laser"/>'
        f'<origin xyz="0 0 0.2" rpy="{scan_rpy}"/></joint>'
        f"{device_joint}</robot>"
    )


def device_on(parent: str, rpy: str, kind: str = "fixed") -> str:
    return (
        f'<joint name="device" type="{kind}"><parent link="{parent}"/><child link="dev"/>'
        f'<origin xyz="0.01 0 0" rpy="{rpy}"/><axis xyz="0 0 1"/></joint>'
    )


BOT = "robot: {urdf: bot.urdf, lidar_link: laser, lidar_device_link: dev}\n"


def test_the_v2_model_puts_the_devices_zero_to_the_right() -> None:
    """The FOSSBot v2's A1 mount comes from fossbot_v2.urdf: zero at -90 deg, clockwise."""
    from harness.lidar.mount import LidarMount
    from harness.scenario import scenario_mount

    scenario = resolve_scenario("approach_wall")
    assert scenario.robot.lidar_device_link == "lidar_device_frame"
    assert scenario_mount(scenario) == LidarMount(yaw_deg=-90.0, mirrored=False)
    assert scenario_mount(scenario).driver_settings() == (True, -90.0)


@pytest.mark.parametrize(
    ("device_joint", "scan_rpy", "yaw", "mirrored"),
    [
        (device_on("laser", "0 0 -1.5707963267948966"), "0 0 0", -90.0, False),
        (device_on("laser", "0 0 3.141592653589793"), "0 0 0", -180.0, False),
        (device_on("laser", "3.141592653589793 0 0"), "0 0 0", 0.0, True),  # upside down
        (device_on("laser", "0 3.141592653589793 0"), "0 0 0", -180.0, True),  # flipped end over
        (device_on("laser", "0.01 0 0.5"), "0 0 0", 28.64788976, False),  # within 1 deg of level
        (device_on("base", "0 0 0"), "0 0 1.5707963267948966", -90.0, False),  # siblings
        (device_on("base", "3.141592653589793 0 0.3"), "0 0 0.3", 0.0, True),
    ],
)
def test_the_mount_is_the_device_links_orientation_in_the_scan_frame(
    tmp_path: Path, device_joint: str, scan_rpy: str, yaw: float, mirrored: bool
) -> None:
    """Yaw of the device's x about the scan frame's z; mirrored when its z points down."""
    from harness.scenario import scenario_mount

    mount_urdf(tmp_path, device_joint, scan_rpy=scan_rpy)
    mount = scenario_mount(load_scenario_file(write(tmp_path, STILL + BOT)))
    assert mount.yaw_deg == pytest.approx(yaw, abs=1e-7)
    assert mount.mirrored is mirrored


def test_the_scan_link_below_the_device_link_is_composed_too(tmp_path: Path) -> None:
    """The device link may be the scan link's parent: the scan frame's own yaw counts."""
    from harness.scenario import scenario_mount

    (tmp_path / "bot.urdf").write_text(
        '<?xml version="1.0"?><robot name="bot"><link name="base"/><link name="dev"/>'
        '<link name="laser"/>'
        '<joint name="a" type="fixed"><parent link="base"/><child link="dev"/></joint>'
        '<joint name="b" type="fixed"><parent link="dev"/><child link="laser"/>'
        '<origin rpy="0 0 0.5"/></joint></robot>'
    )
    mount = scenario_mount(load_scenario_file(write(tmp_path, STILL + BOT)))
    assert mount.yaw_deg == pytest.approx(-28.64788976, abs=1e-7)


def test_a_robot_without_a_device_link_has_the_generic_mount(tmp_path: Path) -> None:
    """Left at its default, a missing lidar_device_frame means zero straight ahead."""
    from harness.lidar.mount import FORWARD
    from harness.scenario import scenario_mount

    mount_urdf(tmp_path, "")
    (tmp_path / "bot.urdf").write_text(
        (tmp_path / "bot.urdf").read_text().replace('<link name="dev"/>', "")
    )
    robot = "robot: {urdf: bot.urdf, lidar_link: laser}\n"
    assert scenario_mount(load_scenario_file(write(tmp_path, STILL + robot))) is FORWARD
    named = write(tmp_path, STILL + BOT, "named.yaml")
    with pytest.raises(
        ConfigError,
        match=rf"^{named}: robot\.lidar_device_link: no link named 'dev' in 'bot\.urdf' "
        r"\(leave the field out",
    ):
        load_scenario_file(named)


@pytest.mark.parametrize(
    ("device_joint", "reason"),
    [
        (
            device_on("laser", "0.5 0 0"),
            r"'dev' in 'bot\.urdf' is tilted 28\.6 deg from the z axis of 'laser'; "
            r"a spinning LIDAR's axis must be parallel to it",
        ),
        (
            device_on("laser", "0 1.5707963267948966 0"),
            r"'dev' in 'bot\.urdf' is tilted 90\.0 deg",
        ),
        (
            device_on("laser", "0 0 0", "continuous"),
            r"'dev' in 'bot\.urdf' is joined to 'laser' through the continuous joint 'device'; "
            r"the device must be fixed to the scan link",
        ),
    ],
)
def test_a_device_that_cannot_be_a_mount_is_refused_at_load(
    tmp_path: Path, device_joint: str, reason: str
) -> None:
    """Tilted, or on a moving joint: one line naming the scenario file, the field and the link."""
    mount_urdf(tmp_path, device_joint)
    path = write(tmp_path, STILL + BOT)
    with pytest.raises(ConfigError, match=rf"^{path}: robot\.lidar_device_link: {reason}"):
        load_scenario_file(path)


def test_a_mount_is_read_once_per_file_version(tmp_path: Path) -> None:
    """The URDF is cached per file; a changed file is read again."""
    from harness.scenario import scenario_mount

    mount_urdf(tmp_path, device_on("laser", "0 0 0.5"))
    scenario = load_scenario_file(write(tmp_path, STILL + BOT))
    assert scenario_mount(scenario).yaw_deg == pytest.approx(28.64788976)
    mount_urdf(tmp_path, device_on("laser", "0 0 -1.0"))
    assert scenario_mount(scenario).yaw_deg == pytest.approx(-57.29577951)
