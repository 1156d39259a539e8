"""Generated scenario files: the harness runs each one or refuses it in one line, nothing else.

Hypothesis builds scenarios that are valid or nearly so (every field, fault
profiles and inline faults from harness/faults/sensor.py), then mutates some of
them: wrong types, missing and extra keys, extreme numbers, random text,
and corrupted YAML text. Some are hostile in ways a loader may quietly get
wrong: numbers written as text, YAML 1.1 number forms (`1_0`, `1:20`,
`010`), floats where a count is meant, other YAML tags, a robot placed in
or against an obstacle, a scan wider than one turn, a threshold beyond
range_max. Each is written to a file and loaded; a scenario
the loader accepts is then really simulated and judged over the inprocess
link. The only exception allowed anywhere is ConfigError, whose message is
one line naming the file. A smaller sample runs through the real
`fossbot-hil run` command to prove the exit codes.

Deterministic (derandomized, no example database, and no local literals in
the draws: see conftest.py) so CI sees the same files every time; each
example is short (valid runs are at most a few simulated seconds and a few
hundred thousand beams).
"""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from harness.errors import ConfigError
from harness.faults.sensor import CONVENTIONS, DROPOUT_VALUES, NAMED_PROFILES
from harness.lidar.spec import PRESETS
from harness.links.base import LinkOptions
from harness.runner.scenario_run import run
from harness.scenario.files import load_scenario_file
from harness.scenario.geometry import cylinder_segments
from harness.scenario.schema import Cylinder, Scenario

IN_PROCESS_EXAMPLES = 250
CLI_EXAMPLES = 20
# A valid scenario is run only if it is this cheap; the generator keeps almost all of them so.
RUN_SECONDS, RUN_BEAMS, RUN_CYLINDER_SIDES = 5.0, 300_000, 20_000

COMMON = settings(
    deadline=None,
    derandomize=True,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

# -- valid-ish scenarios -----------------------------------------------------


def floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


# Obstacles stand on one side of the square (+-1 m) robots start in, CLEAR + their
# reach beyond its edge, so the robot (0.15 m from its origin at most) starts
# clear of them; `crowded` puts one at the start on purpose.
CLEAR = 1.2
SIDES = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]


def beside(draw: st.DrawFn, side: tuple[float, float], reach: float) -> list[float]:
    """A floor point on `side`, far enough out for an obstacle that reaches `reach` around it."""
    (nx, ny), u, v = side, draw(floats(CLEAR + reach, 5.0 + reach)), draw(floats(-5, 5))
    return [nx * u - ny * v, ny * u + nx * v]


@st.composite
def walls(draw: st.DrawFn) -> dict[str, Any]:
    side, thickness = draw(st.sampled_from(SIDES)), draw(floats(0.01, 0.5))
    wall = {"type": "wall", "start": beside(draw, side, thickness), "end": None}
    wall["end"] = beside(draw, side, thickness)
    if draw(st.booleans()):
        wall["thickness"] = thickness
    if draw(st.booleans()):
        wall["height"] = draw(floats(0.05, 2.0))
    return wall


@st.composite
def boxes(draw: st.DrawFn) -> dict[str, Any]:
    size = draw(st.lists(floats(0.01, 2.0), min_size=3, max_size=3))
    where = beside(draw, draw(st.sampled_from(SIDES)), math.hypot(size[0], size[1]) / 2)
    box = {"type": "box", "position": where, "size": size}
    if draw(st.booleans()):
        box["yaw"] = draw(floats(-7, 7))
    return box


@st.composite
def cylinders(draw: st.DrawFn) -> dict[str, Any]:
    radius = draw(floats(0.005, 1.0))
    where = beside(draw, draw(st.sampled_from(SIDES)), radius)
    cylinder = {"type": "cylinder", "position": where, "radius": radius}
    if draw(st.booleans()):
        cylinder["height"] = draw(floats(0.05, 2.0))
    return cylinder


models = st.fixed_dictionaries(
    {
        "type": st.just("model"),
        "path": st.sampled_from(["fossbot_v2.urdf", "missing.urdf", "../up.urdf", "/abs.sdf"]),
    },
    optional={"position": st.lists(floats(-5, 5), min_size=3, max_size=3), "yaw": floats(-4, 4)},
)
obstacles = st.lists(st.one_of(walls(), walls(), boxes(), cylinders(), models), max_size=4)

inline_faults = st.one_of(
    st.fixed_dictionaries({"type": st.just("noise"), "sigma": floats(0, 0.05)}),
    st.fixed_dictionaries(
        {"type": st.just("dropouts"), "rate": floats(0, 0.3)},
        optional={"value": st.sampled_from(sorted(DROPOUT_VALUES))},
    ),
    st.fixed_dictionaries({"type": st.just("spurious"), "rate": floats(0, 0.1)}),
    st.fixed_dictionaries(
        {"type": st.just("convention"), "name": st.sampled_from(sorted(CONVENTIONS))}
    ),
    # Link faults, some out of range (refused) and line faults (refused off serial links).
    st.fixed_dictionaries(
        {"type": st.just("delay"), "mean": floats(-0.1, 0.01)},
        optional={"jitter": floats(0, 0.01)},
    ),
    st.fixed_dictionaries(
        {
            "type": st.sampled_from(["drop", "duplicate", "reorder", "stale_stamps"]),
            "rate": floats(-0.1, 1.1),
        }
    ),
    st.fixed_dictionaries(
        {"type": st.just("rate_drift")},
        optional={"min_hz": floats(0.1, 25), "max_hz": floats(0.1, 25)},
    ),
    st.fixed_dictionaries(
        {
            "type": st.sampled_from(["line_corruption", "line_drops", "line_noise"]),
            "rate": floats(0, 0.01),
        }
    ),
)
faults = st.lists(st.one_of(st.sampled_from(sorted(NAMED_PROFILES)), inline_faults), max_size=4)


def signed(lo: float, hi: float) -> st.SearchStrategy[float]:
    """A speed away from zero, either way."""
    return st.builds(lambda v, s: v * s, floats(lo, hi), st.sampled_from([-1.0, 1.0]))


segments = st.one_of(
    st.fixed_dictionaries(
        {"until": st.fixed_dictionaries({"duration": floats(0.05, 1.0)})},
        optional={"linear": floats(-0.5, 0.5), "angular": floats(-1.5, 1.5)},
    ),
    st.fixed_dictionaries(
        {
            "linear": signed(0.2, 1.0),
            "until": st.fixed_dictionaries({"distance": floats(0.01, 0.3)}),
        }
    ),
    st.fixed_dictionaries(
        {"angular": signed(0.5, 3.0), "until": st.fixed_dictionaries({"turn": floats(0.05, 1.5)})}
    ),
    st.fixed_dictionaries(
        {
            "linear": floats(0.0, 0.5),
            "until": st.fixed_dictionaries(
                {"obstacle_ahead_below": floats(0.1, 3.0), "timeout": floats(0.2, 1.5)}
            ),
        }
    ),
    st.fixed_dictionaries(
        {
            "until": st.fixed_dictionaries(
                {"obstacle_ahead_above": floats(0.1, 3.0), "timeout": floats(0.2, 1.5)}
            )
        },
        optional={"angular": floats(-2, 2)},
    ),
)

TURN = 2 * math.pi
lidar = st.fixed_dictionaries(
    {"preset": st.sampled_from(sorted(PRESETS))},
    optional={
        # counts as floats (360.0) are refused; spans of about one turn either side of 2 pi
        "samples": st.one_of(
            st.integers(1, 720),
            st.sampled_from([359, 360, 361, 362, 450, 451]),
            st.builds(float, st.integers(1, 720)),
        ),
        "angle_min": st.one_of(
            floats(-math.pi, math.pi), st.sampled_from([-TURN, TURN, 3.2, -3.2, 0.0])
        ),
        "angle_increment": st.one_of(
            floats(0.002, 0.1),
            st.sampled_from([TURN / 360, TURN / 359, TURN / 358, TURN / 450, TURN / 449]),
        ),
        "range_min": floats(0.01, 0.3),
        "range_max": floats(1.0, 20.0),
        "rate_hz": floats(1.0, 50.0),
    },
)

scenarios = st.fixed_dictionaries(
    {
        "description": st.text(
            st.characters(categories=["L", "N", "Zs", "P"]), min_size=1, max_size=40
        ),
        "motion": st.fixed_dictionaries(
            {"segments": st.lists(segments, min_size=1, max_size=3)},
            optional={"mode": st.sampled_from(["kinematic", "kinematic", "wheels"])},
        ),
    },
    optional={
        "name": st.from_regex(r"[a-z][a-z0-9_]{0,20}", fullmatch=True),
        "lidar": lidar,
        "robot": st.fixed_dictionaries(
            {},
            optional={
                "start": st.fixed_dictionaries(
                    {}, optional={"x": floats(-1, 1), "y": floats(-1, 1), "yaw": floats(-4, 4)}
                ),
                "lidar_link": st.sampled_from(["lidar_scan_frame", "base_link", "laser"]),
            },
        ),
        "obstacles": obstacles,
        "faults": faults,
        "threshold": st.one_of(floats(0.05, 3.0), st.sampled_from([12.0, 12.5, 25.0])),
        "seed": st.integers(0, 2**32 - 1),
    },
)


@st.composite
def crowded(draw: st.DrawFn) -> dict[str, Any]:
    """A scenario, a quarter of them with a wall, box or cylinder near where the robot starts."""
    data = draw(scenarios)
    if draw(st.integers(0, 3)) != 3:  # hypothesis favours 0: most are not crowded
        return data
    data["zz_crowded"] = True  # a marker for hostile_kinds, removed before dumping
    start = data.get("robot", {}).get("start", {})
    x = start.get("x", 0.0) + draw(floats(-1.0, 1.0))
    y = start.get("y", 0.0) + draw(floats(-1.0, 1.0))
    kind = draw(st.sampled_from(["wall", "box", "cylinder"]))
    if kind == "wall":
        angle = draw(floats(0, math.pi))
        half = draw(floats(0.05, 1.0))
        dx, dy = half * math.cos(angle), half * math.sin(angle)
        blocker = {"type": "wall", "start": [x - dx, y - dy], "end": [x + dx, y + dy]}
        blocker["thickness"] = draw(floats(0.01, 0.3))
    elif kind == "box":
        size = draw(st.lists(floats(0.01, 0.5), min_size=3, max_size=3))
        blocker = {"type": "box", "position": [x, y], "size": size, "yaw": draw(floats(-4, 4))}
    else:
        blocker = {"type": "cylinder", "position": [x, y], "radius": draw(floats(0.005, 0.3))}
    data["obstacles"] = [*data.get("obstacles", []), blocker]
    return data


# -- mutations ---------------------------------------------------------------

weird_values = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-300, 1e300, -1e300, 2**64, 600.0001, 10_000, 16384, 0.5]),
    st.text(max_size=20),
    st.builds(lambda c, n: c * n, st.characters(), st.integers(200, 5000)),
    st.sampled_from(
        [
            "gazebo",
            "wall",
            "cylinder",
            "model",
            "noisy",
            "harsh",
            "wheels",
            "1e-3",
            "fossbot_v2.urdf",
            "../../etc/passwd",
            "/etc/passwd.urdf",
            "\x1b[31mred",
            "a\nb",
            "",
        ]
    ),
    st.lists(st.integers(-3, 3), max_size=3),
    st.dictionaries(st.sampled_from(["type", "x", "duration", "sigma"]), st.integers(), max_size=2),
)
extra_keys = st.one_of(
    st.sampled_from(["sped", "source", "type", "until", "timeout", "x", "samples"]),
    st.text(max_size=8),
    st.integers(0, 3),
)


def places(node: Any) -> Iterator[tuple[Any, Any]]:
    """Every (container, key-or-index) pair in a nested structure."""
    if isinstance(node, dict):
        for key in list(node):
            yield node, key
            yield from places(node[key])
    elif isinstance(node, list):
        for index in range(len(node)):
            yield node, index
            yield from places(node[index])


# Written into the YAML text as they are (yaml.safe_dump would quote them):
# YAML 1.1 number and boolean forms, YAML 1.2 ones, and tags beyond the core schema.
RAW_FORMS = [
    "1_0",
    "1_000.5",
    "1:20",
    "010",
    "0b11",
    "0x10",
    "0o17",
    "+5",
    "1e3",
    ".5",
    "-.inf",
    "yes",
    "off",
    "2024-01-01",
    "!!int 1_0",
    "!!float 1_0",
    "!!float 12",
    "!!str 0.5",
    "!!set {a: null}",
    "!!binary aGk=",
]


def raw_token(index: int) -> str:
    """A placeholder yaml.safe_dump writes plainly, replaced by a RAW_FORMS entry afterwards."""
    return f"zzraw{index}zz"


def hostile_number(draw: st.DrawFn, value: int | float) -> Any:
    """A number written the ways a loose loader would still read as a number."""
    form = draw(st.sampled_from(["text", "text", "float", "raw", "raw"]))
    if form == "text":
        return str(value)  # dumped in quotes: text
    if form == "float":
        return float(value)  # 360.0 where a count is meant
    return raw_token(draw(st.integers(0, len(RAW_FORMS) - 1)))


@st.composite
def mutated(draw: st.DrawFn, base: st.SearchStrategy[dict[str, Any]]) -> dict[str, Any]:
    """A scenario with 0-3 mutations: replace, delete, add a key, wrap, scale, a hostile number."""
    data = copy.deepcopy(draw(base))
    for _ in range(draw(st.integers(0, 3))):
        spots = list(places(data))
        if not spots:  # every key deleted already: nothing left to mutate
            break
        container, key = draw(st.sampled_from(spots))
        action = draw(
            st.sampled_from(["replace", "replace", "delete", "add", "wrap", "scale", "hostile"])
        )
        if action == "hostile":
            numbers = [
                (c, k)
                for c, k in spots
                if isinstance(c[k], (int, float)) and not isinstance(c[k], bool)
            ]
            if numbers:
                container, key = draw(st.sampled_from(numbers))
                container[key] = hostile_number(draw, container[key])
        elif action == "replace":
            container[key] = draw(weird_values)
        elif action == "delete":
            del container[key]
        elif action == "add":
            target = container[key] if isinstance(container[key], dict) else container
            if isinstance(target, dict):
                target[draw(extra_keys)] = draw(weird_values)
        elif action == "wrap":
            container[key] = [container[key]]
        else:
            value = container[key]
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                container[key] = value * draw(st.sampled_from([-1, 0, 1e3, 1e9, 1e-9]))
    return data


@st.composite
def scenario_files(draw: st.DrawFn) -> tuple[bytes, frozenset[str]]:
    """The bytes of a scenario file: mutated data as YAML, sometimes corrupted as text."""
    scenario = draw(mutated(crowded()))
    kinds = hostile_kinds(scenario)
    text = yaml.safe_dump(scenario, allow_unicode=True, sort_keys=False)
    for index, form in enumerate(RAW_FORMS):
        text = text.replace(raw_token(index), form)
    data = text.encode("utf-8")
    corruption = draw(st.sampled_from(["none"] * 8 + ["truncate", "insert", "bytes"]))
    if corruption == "truncate":
        data = data[: draw(st.integers(0, len(data)))]
    elif corruption == "insert":
        at = draw(st.integers(0, len(data)))
        data = data[:at] + draw(st.text(max_size=10)).encode() + data[at:]
    elif corruption == "bytes":
        at = draw(st.integers(0, len(data)))
        data = data[:at] + draw(st.binary(min_size=1, max_size=8)) + data[at:]
    return data, kinds


def hostile_kinds(scenario: dict[str, Any]) -> frozenset[str]:
    """Which hostile forms a generated scenario holds (for the statistics); drops the marker."""
    kinds = set()
    if scenario.pop("zz_crowded", False):
        kinds.add("robot at an obstacle")
    text = repr(scenario)
    if "zzraw" in text:
        kinds.add("YAML 1.1 form or tag")
    if any(isinstance(v, str) and v[:1].isdigit() for _, v in leaves(scenario)):
        kinds.add("number as text")
    lidar = scenario.get("lidar")
    if isinstance(lidar, dict):
        samples, step = lidar.get("samples", 360), lidar.get("angle_increment", TURN / 360)
        if isinstance(samples, float):
            kinds.add("float samples")
        numbers = all(isinstance(v, (int, float)) for v in (samples, step))
        if numbers and (samples - 1) * step > TURN + 1e-5:
            kinds.add("scan wider than a turn")
    threshold = scenario.get("threshold")
    if isinstance(threshold, float) and threshold > 12:
        kinds.add("threshold beyond range_max")
    return frozenset(kinds)


def leaves(node: Any) -> Iterator[tuple[Any, Any]]:
    """(key, value) of every scalar in a nested structure."""
    for container, key in places(node):
        if not isinstance(container[key], (dict, list)):
            yield key, container[key]


# -- the property ------------------------------------------------------------

HOSTILE_KINDS = (
    "robot at an obstacle",
    "YAML 1.1 form or tag",
    "number as text",
    "float samples",
    "scan wider than a turn",
    "threshold beyond range_max",
)


def cheap_enough(scenario: Scenario) -> bool:
    """Whether running this valid scenario stays short here (see RUN_*)."""
    seconds = sum(s.worst_case_seconds() for s in scenario.motion.segments)
    spec = scenario.lidar_spec
    beams = (seconds * spec.rate_hz + 2) * spec.samples
    sides = sum(cylinder_segments(o.radius) for o in scenario.obstacles if isinstance(o, Cylinder))
    return seconds <= RUN_SECONDS and beams <= RUN_BEAMS and sides <= RUN_CYLINDER_SIDES


def check_refusal(err: ConfigError, path: Path) -> None:
    """A refusal is one printable line that names the file."""
    message = str(err)
    assert message and message.isprintable(), repr(message)  # one line, no escapes
    assert message.startswith(f"{path}: "), message


def outcome(path: Path, stats: Counter[str]) -> int | None:
    """Load and (if valid and cheap) run one file: the exit code the CLI should give.

    None when the file is valid but too costly to run here.
    """
    stats["generated"] += 1
    try:
        scenario = load_scenario_file(path)
    except ConfigError as err:
        check_refusal(err, path)
        stats["refused at load"] += 1
        return 2
    if not cheap_enough(scenario):
        stats["valid, too long to run here"] += 1
        return None
    try:
        result = run(scenario, "inprocess", LinkOptions())
    except ConfigError as err:  # a condition not met in time, a robot without wheel joints
        check_refusal(err, path)
        stats["refused while running"] += 1
        return 2
    assert result.records, "a run that started judges at least one scan"
    stats["ran"] += 1
    return 0 if result.ok else 1


@pytest.mark.timeout(300)
@pytest.mark.slow
def test_generated_scenarios_run_or_are_refused(
    tmp_path: Path, record_property: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each generated file is run or refused with one ConfigError line; never anything else."""
    stats: Counter[str] = Counter()

    kinds: Counter[str] = Counter()

    @settings(COMMON, max_examples=IN_PROCESS_EXAMPLES)
    @given(scenario_files())
    def check(example: tuple[bytes, frozenset[str]]) -> None:
        data, hostile = example
        path = tmp_path / f"generated_{stats['generated']}.yaml"
        path.write_bytes(data)
        try:
            code = outcome(path, stats)
        finally:
            path.unlink()
        for kind in hostile:
            kinds[f"{kind}: {'refused' if code == 2 else 'ran or too long'}"] += 1

    check()
    for key, value in (stats + kinds).items():
        record_property(key, value)
    with capsys.disabled():
        print(f"\n[scenario properties, in process] {dict(stats)}\n  hostile: {dict(kinds)}")
    assert stats["generated"] >= IN_PROCESS_EXAMPLES * 0.95  # hypothesis may stop a little short
    assert stats["ran"] >= 30 and stats["refused at load"] >= 60, dict(stats)
    for kind in HOSTILE_KINDS:  # each hostile form is generated, and refused at least sometimes
        assert kinds[f"{kind}: refused"] >= 2, dict(kinds)


@pytest.mark.timeout(300)
@pytest.mark.slow
def test_generated_scenarios_through_the_command(
    tmp_path: Path, record_property: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    """A sample through `fossbot-hil run FILE --link inprocess`: the exit code the run implies,
    and for a refusal exactly one stderr line and no traceback."""
    stats: Counter[str] = Counter()
    codes: Counter[int] = Counter()

    @settings(COMMON, max_examples=CLI_EXAMPLES)
    @given(scenario_files())
    def check(example: tuple[bytes, frozenset[str]]) -> None:
        data, _ = example
        path = tmp_path / f"generated_{stats['generated']}.yaml"
        path.write_bytes(data)
        try:
            expected = outcome(path, stats)
            if expected is None:
                return
            done = subprocess.run(
                [sys.executable, "-m", "harness.cli", "run", str(path), "--link", "inprocess"],
                capture_output=True,
                text=True,
                timeout=60,
            )
        finally:
            path.unlink()
        codes[done.returncode] += 1
        assert "Traceback" not in done.stderr, done.stderr
        assert done.returncode == expected, (expected, done.returncode, done.stderr[-1000:])
        if expected == 2:
            lines = done.stderr.splitlines()
            assert len(lines) == 1 and lines[0].startswith("fossbot-hil: error: "), done.stderr
            assert done.stdout == ""

    check()
    record_property("exit codes", dict(codes))
    with capsys.disabled():
        print(f"\n[scenario properties, command] {dict(stats)} exit codes {dict(codes)}")
    assert stats["generated"] >= CLI_EXAMPLES and codes[2] >= 5 and codes[0] + codes[1] >= 5
