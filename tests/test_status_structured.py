"""Statuses printed as JSON, Python dicts and `key: value` lines, read by their keys."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from gazebo_scans import make_scan

from harness.judge.answers import Answers, Received
from harness.judge.oracle import Oracle
from harness.judge.status import parse_status

INF, NAN = math.inf, math.nan
NONE = (False, None, None)
# The angle the fixtures below print, as Python prints it: full precision.
RIGHT = 1.5707963267948966

# text -> (obstacle claimed, distance, angle)
STRUCTURED: list[tuple[str, tuple[bool, float | None, float | None]]] = [
    # JSON, as json.dumps writes it: Infinity / NaN for "nothing in range"
    (json.dumps({"obstacle": False, "min_distance": INF, "angle": None}), NONE),
    (json.dumps({"obstacle": False, "distance": NAN, "angle": NAN}), NONE),
    (json.dumps({"obstacle_detected": False, "min_range": -INF}), NONE),
    (json.dumps({"detected": False, "distance": INF}), NONE),
    (json.dumps({"obstacle": True, "min_distance": 0.84, "angle": RIGHT}), (True, 0.84, RIGHT)),
    ('{"obstacleDetected": false, "minDistance": Infinity}', NONE),
    ('{"Obstacle": "False", "Distance": "inf"}', NONE),
    ('{"obstacle": null, "distance": 0.5}', NONE),
    ('{"obstacle": 0, "distance": 0.5, "angle": 0.1}', NONE),
    ('{"obstacle": 1, "distance": 0.5, "angle": 0.1}', (True, 0.5, 0.1)),
    ('{"obstacle": 0.84, "angle": 1.57}', (True, 0.84, 1.57)),
    ('{"detected": 1, "range": 0.84, "bearing": -1.57}', (True, 0.84, -1.57)),
    ('{"out_of_range": true, "distance": Infinity}', NONE),
    ('{"clear": false, "distance": 0.4, "angle": 0.2}', (True, 0.4, 0.2)),
    ('{"in_range": false, "distance": Infinity}', NONE),
    # keys beat position: a threshold, a maximum or an index is not the distance
    ('{"threshold": 0.5, "distance": 0.84, "angle_rad": 1.57}', (True, 0.84, 1.57)),
    ('{"range_max": 12.0, "distance": null, "angle": null}', NONE),
    ('{"index": 90, "distance": 0.84, "time": 3.2, "angle": 1.57}', (True, 0.84, 1.57)),
    ('{"obstacle": true, "threshold": 0.5, "distance": 0.84}', (True, 0.84, None)),
    ('{"valid_count": 300, "min_valid": 0.84, "angle": 1.57}', (True, 0.84, 1.57)),
    ('{"min_distance": Infinity, "angle": null}', (True, INF, None)),  # inf is a claim
    ('{"distance": null, "angle": null}', NONE),
    # one level of nesting
    ('{"obstacle": {"distance": 0.5, "angle": 0.1}}', (True, 0.5, 0.1)),
    ('{"obstacle": {"detected": false, "distance": Infinity}}', NONE),
    ('{"obstacle": {"distance": null}}', NONE),
    ('{"nearest": {"distance": 0.5, "bearing": -0.2}, "threshold": 0.3}', (True, 0.5, -0.2)),
    ('{"distance": {"value": 0.5, "unit": "m"}, "angle": 0.1}', (True, 0.5, 0.1)),
    # strings holding numbers, units not converted
    ('{"obstacle": true, "distance": "0.84 m", "angle": "1.57 rad"}', (True, 0.84, 1.57)),
    ('Status: {"obstacle": false, "distance": Infinity}', NONE),
    ("[false, Infinity, null]", NONE),
    # Python literals, as str() of a dict or tuple prints them
    (str({"obstacle": False, "distance": INF}), NONE),
    (str({"obstacle": False, "distance": NAN, "angle": None}), NONE),
    (str({"obstacle": True, "distance": 0.84, "angle": RIGHT}), (True, 0.84, RIGHT)),
    (str({"obstacle": True, "distance": -INF}), (True, -INF, None)),
    (str((False, INF, None)), NONE),
    (str((True, 0.84, 1.57)), (True, 0.84, 1.57)),
    ("{'obstacle': np.False_, 'distance': np.float64(inf)}", NONE),
    (
        "{'obstacle': np.True_, 'distance': np.float32(0.84),"
        " 'angle': np.float64(1.5707963267948966)}",
        (True, 0.84, RIGHT),
    ),
    ("{'obstacle': False, 'distance': float('inf')}", NONE),
    ("{obstacle: false, distance: inf}", NONE),  # bare keys
    ("{obstacle: false, distance: .inf}", NONE),  # a YAML flow mapping
    # key: value lines and pairs, YAML-like
    ("obstacle: false\ndistance: .inf\nangle: null", NONE),
    ("detected: False, distance: inf", NONE),
    ("found: no; range: inf", NONE),
    ("present=0 distance=inf", NONE),
    ("blocked: false\nmin: .inf", NONE),
    ("obstacle: ~", NONE),
    ("obstacle_detected=False min_range=inf angle=nan", NONE),
    ("obstacle: true\nthreshold: 0.5\ndistance: 0.84", (True, 0.84, None)),
    ("obstacle: yes\ndistance: 0.84 m\nbearing: -0.5 rad", (True, 0.84, -0.5)),
    ("obstacle:\n  distance: 0.5\n  angle: 0.1\nthreshold: 0.3", (True, 0.5, 0.1)),
    ("range_max: 12.0, min: 0.5, angle: 0.1", (True, 0.5, 0.1)),
    ("distance: 0.84 m angle: 1.57 rad", (True, 0.84, 1.57)),
]


def _same(a: float | None, b: float | None) -> bool:
    if a is None or b is None:
        return a is b
    return a == b or (math.isnan(a) and math.isnan(b))


@pytest.mark.parametrize("text, expected", STRUCTURED, ids=[t for t, _ in STRUCTURED])
def test_structured_statuses(text: str, expected: tuple[bool, float | None, float | None]) -> None:
    """Each structured status is read by its keys; explicit values beat position."""
    claim = parse_status(text)
    obstacle, distance, angle = expected
    assert claim.unreadable is None, claim.unreadable
    assert claim.obstacle is obstacle, claim
    assert _same(claim.distance, distance), claim
    assert _same(claim.angle, angle), claim


def test_the_issue_statuses_pass_a_clear_scan() -> None:
    """The two statuses of issue 39: json.dumps's Infinity and str() of a dict."""
    scan = make_scan()  # nothing in range
    oracle = Oracle(0.5)
    for text in (
        '{"obstacle": false, "min_distance": Infinity, "angle": null}',
        "{'obstacle': False, 'distance': inf}",
    ):
        v = oracle.judge(0, 0.0, scan, Answers(statuses=[Received(text, 0.01)], waited=0.01))
        assert v.ok, v.explanation


def test_why_no_obstacle_is_claimed() -> None:
    """The key and value that decided it, for explanations."""
    assert parse_status('{"obstacle": false, "distance": 0.5}').reason == "says obstacle: false"
    assert parse_status("{'detected': False}").reason == "says detected: False"
    assert parse_status('{"distance": null}').reason == "says distance: null"
    assert parse_status('{"obstacle": {"distance": null}}').reason == "says obstacle.distance: null"


@pytest.mark.parametrize(
    "text, dd, ad",
    [
        ('{"distance": 0.840, "angle": 1.2e-1}', 3, 2),
        ("{'distance': np.float32(0.84), 'angle': 3}", 2, 0),
        ("distance: 0.8420000076293945\nangle: -1.5", 16, 1),
        ('{"distance": "0.84 m", "angle": "-0.5rad"}', 2, 1),
    ],
)
def test_printed_precision_of_a_key(text: str, dd: int, ad: int) -> None:
    """Tolerances follow the digits the value was printed with, as in free text."""
    claim = parse_status(text)
    assert (claim.distance_decimals, claim.angle_decimals) == (dd, ad)


def test_degrees_under_a_key_are_read_and_judged_wrong() -> None:
    """Units are never converted: a key holding degrees fails as free text does."""
    scan = make_scan({90: 1.0})
    i = 90
    truth = scan.angle_min + i * scan.angle_increment
    text = json.dumps({"obstacle": True, "distance": 1.0, "angle": math.degrees(truth)})
    v = Oracle(0.5).judge(0, 0.0, scan, Answers(statuses=[Received(text, 0.01)], waited=0.01))
    assert not v.ok and "looks like degrees" in v.explanation


# -- free text stays free text ------------------------------------------------------------


@pytest.mark.parametrize(
    "text, expected",
    [
        ('{"msg": "Obstacle at 0.50 m, 0.10 rad"}', (True, 0.5, 0.1)),  # no key says anything
        ('{"status": "No obstacle"}', NONE),
        ("info: 0.5", (True, 0.5, None)),
        ("Free space ahead: 1.2 m", (True, 1.2, None)),
        ("Path is clear (min=inf)", NONE),
        ("Obstacle detected! Min distance: 0.84", (True, 0.84, None)),
        ("t=3.2s obstacle at 0.5 m, angle 0.1", (True, 0.5, 0.1)),
        ("(0.8420000076293945, 1.5707963267948966)", (True, 0.8420000076293945, RIGHT)),
        ("Obstacle [0.5, 1.0]", (True, 0.5, 1.0)),
    ],
)
def test_free_text_that_looks_structured(
    text: str, expected: tuple[bool, float | None, float | None]
) -> None:
    """Texts whose keys name nothing, or that are not pairs throughout, keep the
    free-text reading."""
    claim = parse_status(text)
    assert (claim.obstacle, claim.distance, claim.angle) == expected


@pytest.mark.parametrize(
    "text",
    [
        "[" * 5000,
        '{"a": ' * 3000,
        "{" + "1: 2, " * 2000 + "}",
        "- " * 4000 + "1",
        "x: " * 5000,
        "{'distance': 1" + "0" * 400 + "}",  # too large for a float
        "{'d': 1j, 'e': b'x', **rest}",
    ],
)
def test_hostile_structures_do_not_break_the_reader(text: str) -> None:
    """Deep nesting, long runs: read or left to free text, never an exception."""
    parse_status(text)


# -- what cannot be read ------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, regex_reads",
    [
        ("obstacle: yes-ish", None),  # tests/ros/student_node.py's 'unparseable'
        ('{"obstacle": "maybe", "distance": 0.5, "angle": 0.1}', (True, 0.5, 0.1)),
        ("{'obstacle': True, 'distance': 'far', 'angle': 0.1}", (True, None, 0.1)),
        ("obstacle: perhaps\nmin_distance: 0.84 m", (True, 0.84, None)),
    ],
)
def test_unreadable_structures_say_so_with_a_regex(
    text: str, regex_reads: tuple[bool, float | None, float | None] | None
) -> None:
    """A flag or distance whose value is no bool or number: the status is unreadable,
    the reason names the key and value, and the suggested --status-regex reads it."""
    claim = parse_status(text)
    assert claim.unreadable is not None and not claim.obstacle
    assert "--status-regex" in claim.unreadable
    if regex_reads is None:
        assert "(?P<distance>...)" in claim.unreadable
        return
    m = re.search(r"--status-regex '([^']*)'", claim.unreadable)
    assert m is not None, claim.unreadable
    read = parse_status(text, m.group(1))
    assert (read.obstacle, read.distance, read.angle) == regex_reads


def test_unreadable_status_fails_every_tick_and_quotes_it() -> None:
    """What a status claims is unknown: it fails on a clear scan too, quoting it."""
    oracle = Oracle(0.5)
    for scan in (make_scan(), make_scan({90: 1.0})):
        v = oracle.judge(0, 0.0, scan, Answers(statuses=[Received("obstacle: yes-ish", 0.01)]))
        assert not v.ok
        assert v.failures[0].startswith(
            "cannot read status 'obstacle: yes-ish': its 'obstacle' is 'yes-ish',"
            " neither true nor false; a --status-regex with named groups"
        ), v.failures


def test_an_obstacle_claimed_without_distance_on_a_clear_scan() -> None:
    """{"obstacle": true} alone claims an obstacle and says no distance."""
    v = Oracle(0.5).judge(
        0, 0.0, make_scan(), Answers(statuses=[Received('{"obstacle": true}', 0.01)])
    )
    assert v.failures == ("status '{\"obstacle\": true}' claims an obstacle",)


def test_numpy_values_print_as_the_reader_expects() -> None:
    """str() of a dict of numpy values is read (numpy 1 prints bare numbers, 2 wraps them)."""
    text = str({"obstacle": np.bool_(False), "distance": np.float32(np.inf)})
    assert not parse_status(text).obstacle
    text = str({"obstacle": np.bool_(True), "distance": np.float32(0.84), "angle": np.float64(0.5)})
    claim = parse_status(text)
    assert (claim.obstacle, claim.distance, claim.angle) == (True, pytest.approx(0.84), 0.5)
