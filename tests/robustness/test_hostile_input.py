"""Hostile input: every kind is refused with exit 2 and one line naming it, nothing else.

Scenario files, the model files they name, and command-line options, each
tried the way a user (or an attacker) would. Input refused before anything
starts runs through ``main`` in this process; input that could start a node,
open a port or reach PyBullet's crash-prone parsers runs as a real command,
which must leave no process and no file behind.
"""

from __future__ import annotations

import os
import stat
import struct
from collections.abc import Callable
from pathlib import Path

import pytest
from hostile_checks import (
    Outcome,
    assert_nothing_left,
    assert_refused,
    listing,
    run_command,
    run_in_process,
)

from harness.scenario.model_files import robot_models_dir

pytestmark = pytest.mark.timeout(90)

BASE = """\
description: A wall ahead.
obstacles:
  - {type: wall, start: [2.0, -1.0], end: [2.0, 1.0]}
motion:
  segments:
    - linear: 0.2
      until: {duration: 1.0}
"""
INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
)


def scenario_with(change: str) -> str:
    """BASE with `change` (top-level YAML) replacing the keys it sets."""
    keys = {line.split(":", 1)[0] for line in change.splitlines() if line and line[0].isalpha()}
    kept, skipping = [], False
    for line in BASE.splitlines(keepends=True):
        if line[0].isalpha():
            skipping = line.split(":", 1)[0] in keys
        if not skipping:
            kept.append(line)
    return "".join(kept) + change


def segments(*lines: str) -> str:
    return "motion:\n  segments:\n" + "".join(f"    - {line}\n" for line in lines)


def link(name: str, geometry: str = '<box size="0.1 0.1 0.1"/>', extra: str = "") -> str:
    return (
        f'<link name="{name}">{INERTIAL}<collision><geometry>{geometry}</geometry>'
        f"</collision>{extra}</link>"
    )


def robot(body: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="r">{body}</robot>\n'


def sdf(body: str) -> str:
    box = '<collision name="c"><geometry><box><size>0.2 0.2 0.5</size></box></geometry></collision>'
    return f'<?xml version="1.0"?><sdf version="1.6">{body.replace("BOX", box)}</sdf>'


BILLION_LAUGHS = "".join(
    f"{n}: &{n} [{', '.join([f'*{p}'] * 9)}]\n" for p, n in zip("abcdefgh", "bcdefghi", strict=True)
)

# (id, file contents, phrase the one error line must contain)
SCENARIO_FILES: list[tuple[str, str | bytes, str]] = [
    (
        "wrong_type_list",
        scenario_with(segments("{linear: [1, 2], until: {duration: 1}}")),
        "motion.segments[0].linear: Input should be a valid number",
    ),
    ("wrong_type_text", scenario_with("threshold: abc\n"), "threshold: Input should be a valid"),
    (
        "wrong_type_bool",
        scenario_with("threshold: true\n"),
        "threshold: must be a number, got true",
    ),
    ("wrong_type_mapping", scenario_with("obstacles: {a: 1}\n"), "obstacles: Input should be"),
    ("unknown_key", scenario_with("sped: 3\n"), "sped: unknown key"),
    ("unknown_nested_key", scenario_with("robot: {start: {z: 1}}\n"), "robot.start.z: unknown key"),
    ("missing_motion", "description: nothing moves\n", "motion: required field is missing"),
    ("source_key", scenario_with("source: /etc/passwd\n"), "source: unknown key"),
    ("nan_duration", scenario_with(segments("{until: {duration: .nan}}")), "finite number"),
    ("inf_duration", scenario_with(segments("{until: {duration: .inf}}")), "finite number"),
    ("negative_duration", scenario_with(segments("{until: {duration: -1}}")), "greater than 0"),
    ("zero_duration", scenario_with(segments("{until: {duration: 0}}")), "greater than 0"),
    ("huge_duration", scenario_with(segments("{until: {duration: 1e9}}")), "at most 600 s"),
    ("nan_threshold", scenario_with("threshold: .nan\n"), "threshold: Input should be a finite"),
    (
        "run_too_long",
        scenario_with(segments(*["{until: {duration: 600}}"] * 2)),
        "the run could last 1200 s of simulated time",
    ),
    (
        "too_many_scans",
        scenario_with("lidar: {rate_hz: 100}\n" + segments("{until: {duration: 200}}")),
        "20001 scans at 100 Hz); at most 600 s and 10000 scans",
    ),
    (
        "waiting_counts_at_timeout",
        scenario_with(segments(*["{linear: 0.1, until: {obstacle_ahead_below: 0.3}}"] * 11)),
        "count at their until.timeout",
    ),
    (
        "too_many_beams",
        scenario_with(
            "lidar: {samples: 16383, angle_increment: 0.0003}\n"
            + segments("{until: {duration: 61}}")
        ),
        "beams to cast",
    ),
    (
        "too_many_obstacles",
        "description: x\nobstacles:\n"
        + "  - {type: box, position: [1, 1], size: [0.1, 0.1, 0.1]}\n" * 1001
        + segments("{until: {duration: 1}}"),
        "obstacles: List should have at most 1000 items",
    ),
    (
        "too_many_segments",
        scenario_with(segments(*["{until: {duration: 0.1}}"] * 1001)),
        "motion.segments: List should have at most 1000 items",
    ),
    (
        "too_many_cylinder_sides",
        "description: x\nobstacles:\n"
        + "  - {type: cylinder, position: [50, 50], radius: 100}\n" * 60
        + segments("{until: {duration: 1}}"),
        "mesh sides in all",
    ),
    (
        "too_many_models",
        "description: x\nobstacles:\n"
        + "  - {type: model, path: m.urdf}\n" * 101
        + segments("{until: {duration: 1}}"),
        "101 model obstacles; at most 100",
    ),
    (
        "too_many_faults",
        scenario_with("faults: [" + ", ".join(["noisy"] * 51) + "]\n"),
        "faults: List should have at most 50 items",
    ),
    (
        "huge_coordinate",
        scenario_with("obstacles:\n  - {type: wall, start: [1e300, 0], end: [1, 1]}\n"),
        "obstacles[0].start[0]: Input should be less than or equal to 1000",
    ),
    (
        "huge_radius",
        scenario_with("obstacles:\n  - {type: cylinder, position: [1, 0], radius: 1e300}\n"),
        "obstacles[0].radius: Input should be less than or equal to 100",
    ),
    ("huge_samples", scenario_with("lidar: {samples: 1000000}\n"), "lidar.samples"),
    ("huge_seed", scenario_with("seed: 1099511627776\n"), "seed: Input should be less than"),
    ("huge_range", scenario_with("lidar: {range_max: 1e300}\n"), "lidar.range_max"),
    ("tiny_rate", scenario_with("lidar: {rate_hz: 1e-300}\n"), "lidar.rate_hz"),
    (
        "fault_out_of_range",
        scenario_with("faults: [{type: noise, sigma: 1e400}]\n"),
        "faults[0].sigma: must be in [0, 1]",
    ),
    ("fault_unknown", scenario_with("faults: [sparkles]\n"), "unknown fault profile 'sparkles'"),
    (
        "deep_lists",
        "description: x\nmotion: " + "[" * 100_000 + "]" * 100_000 + "\n",
        "nested deeper than 20 levels",
    ),
    (
        "deep_mappings",
        "description: x\nmotion: " + "{a: " * 5000 + "1" + "}" * 5000 + "\n",
        "nested deeper than 20 levels",
    ),
    (
        "billion_laughs",
        "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n"
        + BILLION_LAUGHS
        + "description: x\nobstacles: *i\n"
        + segments("{until: {duration: 1}}"),
        "more than 100000 values once aliases are expanded",
    ),
    (
        "alias_into_itself",
        scenario_with("obstacles: &loop [*loop]\n"),
        "an alias refers to the value it is inside",
    ),
    ("non_utf8", BASE.encode() + b"name: caf\xe9\n", "not UTF-8 text (byte 0xe9 at line 8)"),
    ("utf16", BASE.encode("utf-16"), "not UTF-8 text"),
    ("nul_byte", BASE.replace("A wall", "A\0wall").encode(), "unacceptable character U+0000"),
    (
        "control_character",
        scenario_with('description: "beep\\a\\e[31m"\n'),
        "description: must be printable text, found character U+0007",
    ),
    ("empty_file", "", "a scenario must be a mapping of fields, got nothing"),
    ("only_comments", "# nothing here\n", "a scenario must be a mapping of fields, got nothing"),
    (
        "a_list",
        "- description: x\n- motion: y\n",
        "a scenario must be a mapping of fields, got a list",
    ),
    ("a_scalar", "42\n", "a scenario must be a mapping of fields, got int"),
    ("two_documents", BASE + "---\n" + BASE, "expected a single document"),
    (
        "long_description",
        scenario_with("description: " + "x" * 300 + "\n"),
        "description: String should have at most 200 characters",
    ),
    (
        "very_long_value",
        scenario_with("description: " + "x" * 100_000 + "\n"),
        "a value longer than 4096 characters",
    ),
    ("very_long_key", BASE + "x" * 2000 + ": 1\n", "YAML error at line 8"),
    ("huge_integer", scenario_with("seed: " + "9" * 5000 + "\n"), "a value longer than 4096"),
    ("larger_than_1mib", BASE + "# " + "x" * (1 << 20) + "\n", "larger than 1 MiB"),
    (
        "duplicate_key",
        BASE + "description: again\n",
        "duplicate key 'description' (first at line 1)",
    ),
    (
        "duplicate_nested_key",
        scenario_with(segments("{until: {duration: 1, duration: 2}}")),
        "duplicate key 'duration'",
    ),
    ("key_not_text", BASE + "1: one\n", "keys must be text, got '1'"),
    (
        "python_tag",
        BASE + "threshold: !!python/object/apply:os.system [echo hi]\n",
        "could not determine a constructor",
    ),
    ("tab_indent", "description: x\n\tmotion: 1\n", "YAML error at line 2"),
    ("blank_description", scenario_with("description: '   '\n"), "description: must not be blank"),
    (
        "no_such_lidar_link",
        scenario_with("robot: {lidar_link: laser}\n"),
        "robot.lidar_link: no link named 'laser' in 'fossbot_v2.urdf' (links: base_footprint",
    ),
    ("name_with_newline", scenario_with('name: "a\\nb"\n'), "name: must be printable text"),
    (
        "escapes_in_a_key",
        BASE + '"a\\nb\\e[31m": 1\n',
        "'a\\nb\\x1b[31m': unknown key",
    ),
    (
        "escapes_in_a_type",
        scenario_with('obstacles: [{type: "a\\nb\\e[31m"}]\n'),
        "obstacles[0]: Input tag 'a\\nb\\x1b[31m' found",
    ),
]


@pytest.mark.parametrize(
    ("contents", "phrase"),
    [pytest.param(c, p, id=i) for i, c, p in SCENARIO_FILES],
)
def test_hostile_scenario_file(
    tmp_path: Path,
    contents: str | bytes,
    phrase: str,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A malformed or hostile scenario file: exit 2, `file: field: problem`, nothing started."""
    path = tmp_path / "hostile.yaml"
    if isinstance(contents, bytes):
        path.write_bytes(contents)
    else:
        path.write_text(contents, encoding="utf-8")
    before = listing(tmp_path)
    outcome = run_in_process(
        ["run", "hostile.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    line = assert_refused(outcome, phrase)
    assert line.startswith("fossbot-hil: error: hostile.yaml: ")
    assert_nothing_left(tmp_path, before)


def test_a_folder_instead_of_a_file(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A folder named like a scenario file."""
    (tmp_path / "folder.yaml").mkdir()
    outcome = run_in_process(
        ["run", "folder.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, "folder.yaml: is a folder, not a scenario file")


def test_file_name_with_a_newline_and_an_escape(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A file name cannot break the one-line message or recolour the terminal."""
    (tmp_path / "new\nline\x1b[31m.yaml").write_text(scenario_with("sped: 1\n"))
    outcome = run_in_process(
        ["run", "new\nline\x1b[31m.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, "new\\nline\\x1b[31m.yaml: sped: unknown key")


def test_missing_file_and_too_long_name(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """No such file, and a name longer than the OS takes: one line each, no traceback."""
    outcome = run_in_process(
        ["run", "nope.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, "nope.yaml: no such scenario file")
    long_path = "a/" * 3000 + "x.yaml"
    outcome = run_in_process(
        ["run", long_path, "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, "File name too long")
    outcome = run_in_process(
        ["run", "a" * 5000, "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, "unknown scenario 'aaaa")


@pytest.mark.parametrize(
    ("make", "phrase"),
    [
        pytest.param(lambda p: os.mkfifo(p), "not a regular file", id="fifo"),
        pytest.param(lambda p: p.symlink_to("/dev/zero"), "not a regular file", id="dev_zero"),
    ],
)
def test_files_that_never_end(tmp_path: Path, make: Callable[[Path], None], phrase: str) -> None:
    """A FIFO nobody writes and /dev/zero: refused at once, neither hangs nor fills memory."""
    path = tmp_path / "endless.yaml"
    make(path)
    before = listing(tmp_path)
    outcome = run_command(["run", "endless.yaml", "--link", "inprocess"], tmp_path, timeout=30)
    assert_refused(outcome, f"endless.yaml: {phrase}")
    assert_nothing_left(tmp_path, before)


# -- model files: where they may come from ----------------------------------

GOOD_URDF = (robot_models_dir() / "fossbot_v2.urdf").read_text()


def _escape_setup(tmp_path: Path) -> Path:
    """tmp/outside.urdf and a scenario folder tmp/scenarios with links pointing out of it."""
    folder = tmp_path / "scenarios"
    (folder / "models").mkdir(parents=True)
    (tmp_path / "outside.urdf").write_text(GOOD_URDF)
    (tmp_path / "outside.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 1) + b"\0" * 50)
    (folder / "escape.urdf").symlink_to(tmp_path / "outside.urdf")
    (folder / "up").symlink_to(tmp_path)
    (folder / "models" / "inside.urdf").write_text(GOOD_URDF)
    return folder


def _mesh_robot(filename: str) -> str:
    return robot(link("base", f'<mesh filename="{filename}"/>'))


# (id, robot.urdf or an obstacle, a model file to write into the scenario folder, phrase)
PATHS: list[tuple[str, str, tuple[str, str] | None, str]] = [
    ("etc_passwd", "robot: {urdf: ../../../etc/passwd}", None, "the robot must be a .urdf file"),
    ("dot_dot", "robot: {urdf: ../outside.urdf}", None, "climbs out of its folder with '..'"),
    ("absolute", "robot: {urdf: /etc/hostname.urdf}", None, "absolute paths are not allowed"),
    ("home", "robot: {urdf: ~/robot.urdf}", None, "absolute paths are not allowed"),
    ("symlinked_file", "robot: {urdf: escape.urdf}", None, "outside"),
    ("symlinked_folder", "robot: {urdf: up/outside.urdf}", None, "outside"),
    (
        "model_dot_dot",
        "obstacles: [{type: model, path: ../../etc/passwd.urdf}]",
        None,
        "obstacles[0].path: cannot load '../../etc/passwd.urdf': climbs out of its folder",
    ),
    (
        "model_absolute",
        "obstacles: [{type: model, path: /etc/x.sdf}]",
        None,
        "obstacles[0].path: cannot load '/etc/x.sdf': absolute paths are not allowed",
    ),
    (
        "model_not_a_model",
        "obstacles: [{type: model, path: notes.txt}]",
        None,
        "model path must end in .urdf or .sdf",
    ),
    (
        "mesh_absolute",
        "robot: {urdf: m.urdf, lidar_link: base}",
        ("m.urdf", _mesh_robot("/etc/passwd.stl")),
        "mesh '/etc/passwd.stl': absolute paths",
    ),
    (
        "mesh_dot_dot",
        "robot: {urdf: m.urdf, lidar_link: base}",
        ("m.urdf", _mesh_robot("../outside.stl")),
        "mesh '../outside.stl': climbs out",
    ),
    (
        "mesh_symlinked",
        "robot: {urdf: m.urdf, lidar_link: base}",
        ("m.urdf", _mesh_robot("up/outside.stl")),
        "mesh 'up/outside.stl': resolves to",
    ),
    (
        "mesh_uri",
        "robot: {urdf: m.urdf, lidar_link: base}",
        ("m.urdf", _mesh_robot("http://example.com/m.stl")),
        "unsupported URI",
    ),
    ("name_too_long", "robot: {urdf: " + "a" * 300 + ".urdf}", None, "no such file"),
]


@pytest.mark.parametrize(
    ("field", "model", "phrase"),
    [pytest.param(f, m, p, id=i) for i, f, m, p in PATHS],
)
def test_model_paths_stay_inside(
    tmp_path: Path,
    field: str,
    model: tuple[str, str] | None,
    phrase: str,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Model and mesh paths out of the scenario's folder (or robot_models/) are refused."""
    folder = _escape_setup(tmp_path)
    if model is not None:
        (folder / model[0]).write_text(model[1])
    (folder / "s.yaml").write_text(scenario_with(field + "\n"))
    before = listing(tmp_path)
    outcome = run_in_process(
        ["run", "scenarios/s.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert_refused(outcome, phrase)
    assert_nothing_left(tmp_path, before)


def test_paths_inside_still_work(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The rule refuses only escapes: subfolders, inner symlinks and robot_models/ load."""
    folder = _escape_setup(tmp_path)
    (folder / "link.urdf").symlink_to(folder / "models" / "inside.urdf")
    field = (
        "robot: {urdf: models/../models/inside.urdf}\n"
        "obstacles: [{type: model, path: link.urdf, position: [3, 0, 0]},"
        " {type: model, path: fossbot_v2.urdf, position: [0, 3, 0]}]\n"
    )
    (folder / "s.yaml").write_text(scenario_with(field))
    outcome = run_in_process(
        ["run", "scenarios/s.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch
    )
    assert outcome.code == 0, outcome
    assert outcome.stderr == "" and "PASS" in outcome.stdout


# -- model files: what PyBullet can take ---------------------------------------

BINARY_STL = b"\0" * 80 + struct.pack("<I", 1) + b"\0" * 50

# (id, model file name, its contents, extra files, phrase); crash=True: PyBullet
# killed the process on these before they were checked, so they run as a command.
MODELS: list[tuple[str, str, str | bytes, dict[str, str | bytes], str, bool]] = [
    ("not_xml", "r.urdf", "this is not xml {", {}, "not well-formed XML: syntax error", False),
    ("empty", "r.urdf", "", {}, "not well-formed XML: no element found", False),
    ("binary", "r.urdf", bytes(range(256)), {}, "not well-formed XML", False),
    (
        "xml_not_robot",
        "r.urdf",
        '<?xml version="1.0"?><sdf/>',
        {},
        "not a URDF: the root element is <sdf>, not <robot>",
        False,
    ),
    ("no_links", "r.urdf", robot(""), {}, "the robot has no <link>", False),
    (
        "link_without_name",
        "r.urdf",
        robot(f"<link>{INERTIAL}</link>"),
        {},
        "a <link> without a name",
        False,
    ),
    ("duplicate_links", "r.urdf", robot(link("a") + link("a")), {}, "two links named 'a'", False),
    (
        "link_name_with_newline",
        "r.urdf",
        robot(link("a&#10;b")),
        {},
        "a <link> name with control characters: 'a\\nb'",
        False,
    ),
    ("two_root_links", "r.urdf", robot(link("a") + link("b")), {}, "2 root links ('a', 'b')", True),
    (
        "joint_loop",
        "r.urdf",
        robot(
            link("a")
            + link("b")
            + '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
            + '<joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>'
        ),
        {},
        "no root link: the joints form a loop",
        False,
    ),
    (
        "joint_to_nowhere",
        "r.urdf",
        robot(
            link("a") + '<joint name="j" type="fixed"><parent link="a"/><child link="zz"/></joint>'
        ),
        {},
        "joint 'j': child link 'zz' does not exist",
        False,
    ),
    (
        "unknown_joint_type",
        "r.urdf",
        robot(
            link("a")
            + link("b")
            + '<joint name="j" type="warp"><parent link="a"/><child link="b"/></joint>'
        ),
        {},
        "joint 'j': unknown type 'warp'",
        False,
    ),
    (
        "zero_axis",
        "r.urdf",
        robot(
            link("a") + link("b") + '<joint name="j" type="revolute"><parent link="a"/>'
            '<child link="b"/><axis xyz="0 0 0"/></joint>'
        ),
        {},
        "axis xyz is the zero vector",
        False,
    ),
    (
        "words_for_numbers",
        "r.urdf",
        robot(link("a", '<box size="x y z"/>')),
        {},
        "link 'a' collision <box> size: expected 3 positive numbers, got 'x y z'",
        False,
    ),
    (
        "nan_size",
        "r.urdf",
        robot(link("a", '<sphere radius="nan"/>')),
        {},
        "<sphere> radius: expected a positive number",
        False,
    ),
    (
        "negative_size",
        "r.urdf",
        robot(link("a", '<box size="-1 0 1"/>')),
        {},
        "expected 3 positive numbers",
        False,
    ),
    (
        "bad_mass",
        "r.urdf",
        robot('<link name="a"><inertial><mass value="abc"/></inertial></link>'),
        {},
        "link 'a' mass: expected a finite number, got 'abc'",
        False,
    ),
    (
        "no_shape",
        "r.urdf",
        robot(link("a", "")),
        {},
        "<geometry> needs exactly one shape, got 0",
        False,
    ),
    (
        "unknown_shape",
        "r.urdf",
        robot(link("a", '<torus r="1"/>')),
        {},
        "unknown shape <torus>",
        False,
    ),
    (
        "entities",
        "r.urdf",
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">]>'
        + robot(link("&a;")).split("?>", 1)[1],
        {},
        "DOCTYPE and ENTITY declarations are not allowed",
        False,
    ),
    (
        "larger_than_5mib",
        "r.urdf",
        robot(link("a")) + "<!--" + "x" * (5 << 20) + "-->",
        {},
        "larger than 5 MiB",
        False,
    ),
    (
        "mesh_missing",
        "r.urdf",
        _mesh_robot("meshes/missing.stl"),
        {},
        "mesh 'meshes/missing.stl': no such file",
        False,
    ),
    (
        "mesh_is_a_folder",
        "r.urdf",
        _mesh_robot("folder.stl"),
        {"folder.stl/": ""},
        "folder.stl is a folder",
        True,
    ),
    (
        "mesh_not_a_mesh",
        "r.urdf",
        _mesh_robot("garbage.stl"),
        {"garbage.stl": b"\0\xff" * 100},
        "not an STL mesh",
        False,
    ),
    (
        "mesh_empty",
        "r.urdf",
        _mesh_robot("empty.obj"),
        {"empty.obj": b""},
        "the mesh file is empty",
        False,
    ),
    (
        "mesh_kind_unknown",
        "r.urdf",
        _mesh_robot("m.ply"),
        {"m.ply": b"ply\n"},
        "PyBullet reads only .stl, .obj, .dae meshes",
        False,
    ),
    ("model_is_a_folder", "r.urdf/", "", {}, "is a folder", False),
    (
        "sdf_not_sdf",
        "r.sdf",
        robot(link("a")),
        {},
        "not an SDF file: the root element is <robot>",
        False,
    ),
    ("sdf_no_model", "r.sdf", sdf(""), {}, "no <model>", False),
    (
        "sdf_model_without_links",
        "r.sdf",
        sdf('<model name="m"/>'),
        {},
        "model 'm': has no <link>",
        False,
    ),
    (
        "sdf_two_links_no_joint",
        "r.sdf",
        sdf(
            '<model name="m"><static>true</static>'
            '<link name="a">BOX</link><link name="b">BOX</link></model>'
        ),
        {},
        "model 'm': 2 root links",
        True,
    ),
    (
        "sdf_include",
        "r.sdf",
        sdf("<world name='w'><include><uri>model://x</uri></include></world>"),
        {},
        "<include> is not supported",
        False,
    ),
    (
        "sdf_mesh_missing",
        "r.sdf",
        sdf(
            '<model name="m"><link name="a"><collision name="c"><geometry><mesh><uri>model://x/m.stl'
            "</uri></mesh></geometry></collision></link></model>"
        ),
        {},
        "mesh 'model://x/m.stl': no such file",
        False,
    ),
]


def _write_model(
    folder: Path, name: str, contents: str | bytes, extra: dict[str, str | bytes]
) -> None:
    for path, data in [(name, contents), *extra.items()]:
        if path.endswith("/"):
            (folder / path).mkdir()
        elif isinstance(data, bytes):
            (folder / path).write_bytes(data)
        else:
            (folder / path).write_text(data)


def _model_scenario(name: str) -> str:
    if name.rstrip("/").endswith(".urdf"):
        field = f"robot: {{urdf: {name.rstrip('/')}, lidar_link: a}}\n"
    else:
        field = f"obstacles: [{{type: model, path: {name}}}]\n"
    return scenario_with(field)


@pytest.mark.parametrize(
    ("name", "contents", "extra", "phrase", "crash"),
    [pytest.param(n, c, e, p, x, id=i) for i, n, c, e, p, x in MODELS],
)
def test_broken_model_file(
    tmp_path: Path,
    name: str,
    contents: str | bytes,
    extra: dict[str, str | bytes],
    phrase: str,
    crash: bool,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A URDF/SDF PyBullet would choke on, print garbage about or crash on: one line instead."""
    _write_model(tmp_path, name, contents, extra)
    (tmp_path / "s.yaml").write_text(_model_scenario(name))
    before = listing(tmp_path)
    args = ["run", "s.yaml", "--link", "inprocess"]
    if crash:
        outcome = run_command(args, tmp_path)
        assert outcome.code >= 0, f"killed by signal {-outcome.code}"
    else:
        outcome = run_in_process(args, tmp_path, capfd, monkeypatch)
    line = assert_refused(outcome, phrase)
    field = "robot.urdf" if name.rstrip("/").endswith(".urdf") else "obstacles[0].path"
    assert line.startswith(f"fossbot-hil: error: s.yaml: {field}: cannot load ")
    assert_nothing_left(tmp_path, before)


# -- command-line options ----------------------------------------------------


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    """A working folder with a good scenario, a regular file, a folder and an empty workspace."""
    (tmp_path / "s.yaml").write_text(BASE)
    (tmp_path / "regular_file").write_text("not a port\n")
    (tmp_path / "a_folder").mkdir()
    (tmp_path / "not_executable").write_text("#!/bin/sh\n")
    (tmp_path / "not_executable").chmod(stat.S_IRUSR | stat.S_IWUSR)
    os.mkfifo(tmp_path / "a_fifo")  # not a regular file; never /dev/null: a writer run as
    return tmp_path  # root would replace the device itself


# (id, arguments after the command, phrase); all could start a node or open a port.
OPTIONS: list[tuple[str, list[str], str]] = [
    (
        "node_not_on_path",
        ["run", "s.yaml", "--node", "no_such_program"],
        "'no_such_program' not found on PATH",
    ),
    (
        "node_no_such_file",
        ["run", "s.yaml", "--node", "./no_such_program --flag"],
        "no such file ./no_such_program",
    ),
    (
        "node_not_executable",
        ["run", "s.yaml", "--node", "./not_executable"],
        "./not_executable is not executable",
    ),
    ("node_folder", ["run", "s.yaml", "--node", "./a_folder"], "no such file ./a_folder"),
    ("node_empty", ["run", "s.yaml", "--node", ""], "argument --node: must not be empty"),
    ("node_blank", ["run", "s.yaml", "--node", "   "], "argument --node: must not be empty"),
    ("node_bad_quoting", ["run", "s.yaml", "--node", "python3 'unclosed"], "No closing quotation"),
    (
        "package_without_workspace",
        ["run", "s.yaml", "--package", "p", "--executable", "e"],
        "--package needs --workspace DIR",
    ),
    (
        "package_without_executable",
        ["run", "s.yaml", "--package", "p"],
        "--package and --executable go together",
    ),
    (
        "executable_empty",
        ["run", "s.yaml", "--package", "p", "--executable", ""],
        "argument --executable: must not be empty",
    ),
    (
        "workspace_missing",
        ["run", "s.yaml", "--package", "p", "--executable", "e", "--workspace", "no_such_ws"],
        "--workspace no_such_ws: no such folder",
    ),
    (
        "workspace_a_file",
        ["run", "s.yaml", "--package", "p", "--executable", "e", "--workspace", "regular_file"],
        "--workspace regular_file: no such folder",
    ),
    (
        "workspace_not_built",
        ["run", "s.yaml", "--package", "p", "--executable", "e", "--workspace", "a_folder"],
        "no colcon install folder",
    ),
    (
        "workspace_empty",
        ["run", "s.yaml", "--package", "p", "--executable", "e", "--workspace", ""],
        "argument --workspace: must not be empty",
    ),
    ("param_no_equals", ["run", "s.yaml", "--param", "threshold"], "expected NAME:=VALUE"),
    ("param_no_name", ["run", "s.yaml", "--param", ":=1"], "expected NAME:=VALUE"),
    ("param_space_in_name", ["run", "s.yaml", "--param", "a b:=1"], "expected NAME:=VALUE"),
    (
        "param_unparsable_value",
        ["run", "s.yaml", "--param", "a:=[unclosed"],
        "ROS 2 cannot parse 'a:=[unclosed'",
    ),
    ("param_bad_name", ["run", "s.yaml", "--param", "1a:=1"], "ROS 2 cannot parse '1a:=1'"),
    ("param_mixed_list", ["run", "s.yaml", "--param", 'a:=[1, "a"]'], "Sequence should be of same"),
    (
        "param_for_inprocess",
        ["run", "s.yaml", "--link", "inprocess", "--param", "a:=1"],
        "--param needs a link that runs a node",
    ),
    (
        "link_unknown",
        ["run", "s.yaml", "--link", "carrier_pigeon"],
        "unknown link 'carrier_pigeon'",
    ),
    (
        "port_missing",
        ["run", "s.yaml", "--link", "rplidar", "--port", "/dev/does_not_exist"],
        "--port /dev/does_not_exist: no such device",
    ),
    (
        "port_regular_file",
        ["run", "s.yaml", "--link", "ldlidar", "--port", "regular_file"],
        "--port regular_file: not a serial port",
    ),
    (
        "port_folder",
        ["run", "s.yaml", "--link", "rplidar", "--port", "a_folder"],
        "--port a_folder: a folder, not a serial port",
    ),
    (
        "port_empty",
        ["run", "s.yaml", "--link", "rplidar", "--port", ""],
        "--port must not be empty",
    ),
    (
        "port_not_a_tty",
        ["run", "s.yaml", "--link", "rplidar", "--port", "/dev/null"],
        "--port /dev/null: cannot open",
    ),
    ("port_for_ros2", ["run", "s.yaml", "--port", "regular_file"], "not a serial port"),
    (
        "emulate_port_missing",
        ["emulate", "rplidar", "--scenario", "s.yaml", "--port", "/dev/does_not_exist"],
        "--port /dev/does_not_exist: no such device",
    ),
    (
        "emulate_port_regular_file",
        ["emulate", "ldlidar", "--scenario", "s.yaml", "--port", "regular_file"],
        "--port regular_file: not a serial port",
    ),
    (
        "emulate_port_folder",
        ["emulate", "rplidar", "--scenario", "s.yaml", "--port", "a_folder"],
        "--port a_folder: a folder, not a serial port",
    ),
    (
        "emulate_bad_scenario",
        ["emulate", "rplidar", "--scenario", "regular_file"],
        "regular_file: a scenario must be a mapping of fields, got text",
    ),
    # Issue 12 item 3: a topic rclpy refuses was a traceback from inside the ros2 link.
    (
        "scan_topic_not_a_topic",
        ["run", "s.yaml", "--scan-topic", "not a topic"],
        "--scan-topic 'not a topic': topic name must not contain characters other than",
    ),
    (
        "status_topic_is_scan_topic",
        ["run", "s.yaml", "--status-topic", "scan"],
        "--status-topic 'scan': the same topic as --scan-topic '/scan' (/scan)",
    ),
    # Issue 12 item 8: parameters the node would never get right.
    (
        "threshold_param_bad_name",
        ["run", "s.yaml", "--threshold-param", "bad name!"],
        "--threshold-param 'bad name!': a parameter name is words",
    ),
    (
        "param_sets_the_threshold",
        ["run", "s.yaml", "--threshold", "0.5", "--param", "threshold:=0.1"],
        "the node and the oracle would disagree; use --threshold 0.1 instead",
    ),
    (
        "param_sets_the_threshold_without_threshold_option",
        ["run", "s.yaml", "--param", "threshold:=0.1"],
        "--param 'threshold:=0.1' sets 'threshold', the parameter the harness passes",
    ),
    (
        "param_sets_the_renamed_threshold",
        ["run", "s.yaml", "--threshold-param", "min_dist", "--param", "min_dist:=0.2"],
        "--param 'min_dist:=0.2' sets 'min_dist'",
    ),
    (
        "param_sets_the_threshold_for_one_node",
        ["run", "s.yaml", "--param", "fossbot_lidar_node:threshold:=0.1"],
        "sets 'threshold', the parameter the harness passes the threshold in",
    ),
    (
        "param_given_twice",
        ["run", "s.yaml", "--param", "lidar_topic:=/a", "--param", "lidar_topic:=/b"],
        "--param 'lidar_topic:=/a' and --param 'lidar_topic:=/b' set the same parameter",
    ),
    (
        "replay_scan_topic_not_a_topic",
        ["replay", "regular_file", "--scan-topic", "not a topic"],
        "--scan-topic 'not a topic': topic name must not contain",
    ),
]


@pytest.mark.ros
@pytest.mark.parametrize(("args", "phrase"), [pytest.param(a, p, id=i) for i, a, p in OPTIONS])
def test_hostile_option(workdir: Path, args: list[str], phrase: str) -> None:
    """A node, package, workspace, parameter or port that cannot work: refused before it starts."""
    before = listing(workdir)
    outcome = run_command(args, workdir)
    assert_refused(outcome, phrase)
    assert_nothing_left(workdir, before)


# (id, arguments, phrase): names, topics and output paths refused before anything
# starts, so they run through `main` in this process.
NAMES_AND_PATHS: list[tuple[str, list[str], str]] = [
    *[
        (f"run_{i}", ["run", "s.yaml", "--link", "inprocess", *args], phrase)
        for i, args, phrase in [
            (
                "scan_topic_spaces",
                ["--scan-topic", "not a topic"],
                "--scan-topic 'not a topic': topic name must not contain characters other than",
            ),
            ("status_topic_empty", ["--status-topic", ""], "--status-topic '': topic name must"),
            ("warning_topic_blank", ["--warning-topic", " "], "--warning-topic ' ': topic name"),
            ("scan_topic_double_slash", ["--scan-topic", "/a//b"], "repeated '/' (character 4)"),
            ("scan_topic_trailing_slash", ["--scan-topic", "/scan/"], "end with a forward slash"),
            ("scan_topic_digit", ["--scan-topic", "/robot/2d"], "must not start with a number"),
            ("scan_topic_private", ["--scan-topic", "~/scan"], "a private name (~) resolves"),
            ("scan_topic_substitution", ["--scan-topic", "{node}/scan"], "substitutions ({node}"),
            ("scan_topic_too_long", ["--scan-topic", "a" * 300], "301 characters, at most 247"),
            (
                "scan_topic_escapes",
                ["--scan-topic", "/scan\x1b[31m\n"],
                "--scan-topic '/scan\\x1b[31m\\n': topic name must not contain",
            ),
            (
                "status_topic_is_scan_topic",
                ["--status-topic", "/scan"],
                "--status-topic '/scan': the same topic as --scan-topic '/scan' (/scan)",
            ),
            (
                "warning_topic_is_status_topic_relative",
                ["--warning-topic", "lidar_status"],
                "--warning-topic 'lidar_status': the same topic as --status-topic",
            ),
            (
                "scan_topic_is_warning_topic",
                ["--scan-topic", "obstacle_warning"],
                "--warning-topic '/obstacle_warning': the same topic as --scan-topic",
            ),
            (
                "threshold_param_bad_name",
                ["--threshold-param", "bad name!"],
                "--threshold-param 'bad name!': a parameter name is words",
            ),
            ("threshold_param_digit", ["--threshold-param", "1x"], "a parameter name is words"),
            ("out_empty", ["--out", ""], "argument --out: must not be empty"),
            ("out_a_file", ["--out", "regular_file"], "regular_file: exists and is not a folder"),
            ("junit_empty", ["--junit-xml", ""], "argument --junit-xml: must not be empty"),
            ("junit_a_folder", ["--junit-xml", "a_folder"], "--junit-xml a_folder: a folder"),
            ("junit_slash", ["--junit-xml", "new/"], "--junit-xml new/: names a folder"),
            ("junit_fifo", ["--junit-xml", "a_fifo"], "a_fifo: exists and is not a regular"),
            ("junit_no_folder", ["--junit-xml", "no/x.xml"], "its folder does not exist"),
            ("junit_through_a_file", ["--junit-xml", "regular_file/x"], "a part of this path"),
        ]
    ],
    (
        "replay_topic_spaces",
        ["replay", "regular_file", "--link", "inprocess", "--topic", "bad topic"],
        "--topic 'bad topic': topic name must not contain",
    ),
    (
        "replay_topic_private",
        ["replay", "regular_file", "--link", "inprocess", "--topic", "~/scan"],
        "--topic '~/scan': a private name",
    ),
    (
        "replay_topic_empty",
        ["replay", "regular_file", "--link", "inprocess", "--topic", ""],
        "--topic '': topic name must not be empty",
    ),
    (
        "replay_status_topic_is_scan_topic",
        ["replay", "regular_file", "--link", "inprocess", "--status-topic", "/scan"],
        "--status-topic '/scan': the same topic as --scan-topic",
    ),
    (
        "replay_record_a_folder",
        ["replay", "regular_file", "--link", "inprocess", "--record", "a_folder"],
        "--record a_folder: a folder, not a file",
    ),
    (
        "replay_record_empty",
        ["replay", "regular_file", "--link", "inprocess", "--record", ""],
        "argument --record: must not be empty",
    ),
    (
        "replay_junit_a_folder",
        ["replay", "regular_file", "--link", "inprocess", "--junit-xml", "a_folder/"],
        "--junit-xml a_folder/: names a folder",
    ),
    (
        "grade_scan_topic_spaces",
        ["grade", "a_folder", "--scan-topic", "x y"],
        "--scan-topic 'x y': topic name must not contain",
    ),
    (
        "grade_warning_topic_is_scan_topic",
        ["grade", "a_folder", "--warning-topic", "/scan"],
        "--warning-topic '/scan': the same topic as --scan-topic",
    ),
    (
        "grade_param_sets_the_threshold",
        ["grade", "a_folder", "--param", "threshold:=0.2"],
        "the node and the oracle would disagree; use --threshold 0.2 instead",
    ),
    (
        "bad_topic_with_out_creates_no_folder",
        ["run", "--out", "new_report", "--scan-topic", "a b"],
        "--scan-topic 'a b': topic name must not contain",
    ),
    (
        "param_sets_use_sim_time",
        ["run", "--param", "use_sim_time:=false"],
        "sets use_sim_time, which the harness passes itself",
    ),
    (
        "grade_param_given_twice",
        ["grade", "a_folder", "--param", "a:=1", "--param", "a:=2"],
        "set the same parameter",
    ),
    (
        "grade_threshold_param_bad_name",
        ["grade", "a_folder", "--threshold-param", "x-y"],
        "--threshold-param 'x-y': a parameter name is words",
    ),
    ("grade_out_empty", ["grade", "a_folder", "--out", ""], "argument --out: must not be empty"),
]


@pytest.mark.parametrize(
    ("args", "phrase"), [pytest.param(a, p, id=i) for i, a, p in NAMES_AND_PATHS]
)
def test_hostile_name_or_path_option(
    workdir: Path,
    args: list[str],
    phrase: str,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A topic or parameter name ROS 2 refuses, two roles on one topic, a parameter that
    fights the harness, or an output path that cannot be written: exit 2, one line."""
    before = listing(workdir)
    outcome = run_in_process(args, workdir, capfd, monkeypatch)
    assert_refused(outcome, phrase)
    assert_nothing_left(workdir, before)


def test_emulate_with_an_empty_port_is_refused(workdir: Path) -> None:
    """`emulate --port ''` should be refused like `run --port ''`."""
    outcome = run_command(["emulate", "rplidar", "--scenario", "s.yaml", "--port", ""], workdir)
    assert_refused(outcome, "--port must not be empty")


def test_emulate_with_bad_faults_exits_2(workdir: Path) -> None:
    """`emulate --faults bogus`: exit 2, one line naming the profile."""
    outcome = run_command(
        ["emulate", "ldlidar", "--scenario", "s.yaml", "--faults", "bogus"], workdir
    )
    assert_refused(Outcome(outcome.code, "", outcome.stderr), "unknown fault profile 'bogus'")


def test_emulate_with_bad_faults_prints_nothing(workdir: Path) -> None:
    """`emulate --faults bogus` should print nothing on stdout before refusing."""
    outcome = run_command(
        ["emulate", "ldlidar", "--scenario", "s.yaml", "--faults", "bogus"], workdir
    )
    assert outcome.stdout == ""


def test_wheels_mode_needs_wheel_joints(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Wheels mode with a robot that has no wheel joints is refused when the file loads."""
    (tmp_path / "r.urdf").write_text(robot(link("a")))
    text = scenario_with("robot: {urdf: r.urdf, lidar_link: a}\n").replace(
        "motion:\n", "motion:\n  mode: wheels\n"
    )
    (tmp_path / "s.yaml").write_text(text)
    outcome = run_in_process(["run", "s.yaml", "--link", "inprocess"], tmp_path, capfd, monkeypatch)
    assert_refused(outcome, "motion.mode: wheels mode needs a revolute joint 'left_wheel_joint'")


def test_scenario_checks_come_before_the_node(workdir: Path) -> None:
    """A bad model file fails the run before the ros2 link starts any node."""
    (workdir / "m.yaml").write_text(scenario_with("robot: {urdf: missing.urdf}\n"))
    before = listing(workdir)
    outcome = run_command(["run", "m.yaml", "--node", "sleep 60"], workdir, timeout=30)
    assert_refused(outcome, "robot.urdf: cannot load 'missing.urdf': no such file")
    assert_nothing_left(workdir, before)
