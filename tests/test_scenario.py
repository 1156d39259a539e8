"""Scenario files: the shipped ones load, and every kind of mistake is one clear line."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.scenario import load_scenario_file, resolve_scenario, shipped_scenarios

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
