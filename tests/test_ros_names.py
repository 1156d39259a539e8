"""ROS 2 names (harness.ros.names): the pure rules agree with rclpy's, and the harness's policy.

The pure-Python rules decide where rclpy is not installed; where it is,
rclpy is asked too. The property tests below generate names that are
valid or nearly so, from the characters that matter to the rules, and
require the same verdict (and, for topics, the same reason and index) from
both, so the two cannot drift apart unnoticed.
"""

from __future__ import annotations

import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from harness.ros import names as ros_names
from harness.ros.names import (
    InvalidName,
    check_parameter_name,
    check_parameter_rule,
    full_topic_name_problem,
    parameter_name_problem,
    parameter_target,
    resolve_topic,
    topic_name_problem,
)

AGREEMENT = settings(
    max_examples=600,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

# Pieces of near-valid names: the brief's alphabet plus whole tokens, so
# that both verdicts come up often.
TOPIC_PIECES = st.one_of(
    st.sampled_from(list("abc_/~{}0 9.-")),
    st.sampled_from(["scan", "/", "~/", "{node}", "{ns}", "_x", "9", "//", "a1"]),
)
TOPICS = st.one_of(
    st.lists(TOPIC_PIECES, max_size=10).map("".join),
    st.lists(TOPIC_PIECES, max_size=10).map(lambda p: "/" + "".join(p)),
    st.integers(240, 260).map(lambda n: "/" + "a" * (n - 1)),  # around the length limit
    st.integers(1, 60).map(lambda n: "/" + "/".join(["ab"] * n)),
)
PARAM_PIECES = st.one_of(
    st.sampled_from(list("ab_r/.:*~0 9-\\")),
    st.sampled_from(
        ["x", "threshold", "__ns", "__node", "__name", "__", "rostopic://", "rosservice://"]
    ),
    st.sampled_from(["rostopic:", "rostopic:/", "ros", "node:", "a_", "_1"]),
)
PARAM_NAMES = (
    st.lists(PARAM_PIECES, min_size=1, max_size=8).map("".join).filter(lambda s: ":=" not in s)
)


def _rclpy_accepts_topic(name: str, *, full: bool) -> bool:
    from rclpy.exceptions import InvalidTopicNameException
    from rclpy.validate_full_topic_name import validate_full_topic_name
    from rclpy.validate_topic_name import validate_topic_name

    try:
        (validate_full_topic_name if full else validate_topic_name)(name)
    except InvalidTopicNameException:
        return False
    return True


def _rclpy_accepts_rule(rule: str) -> bool:
    from rclpy.utilities import remove_ros_args

    try:
        remove_ros_args(["fossbot-hil", "--ros-args", "-p", rule])
    except Exception:  # noqa: BLE001 - RCLInvalidROSArgsError and kin
        return False
    return True


@pytest.mark.ros
@AGREEMENT
@given(TOPICS)
def test_topic_rules_agree_with_rclpy(name: str) -> None:
    """rcl_validate_topic_name and rmw_validate_full_topic_name, same verdict, reason and index."""
    for full, pure in ((False, topic_name_problem), (True, full_topic_name_problem)):
        ours = pure(name)
        assert (ours is None) == _rclpy_accepts_topic(name, full=full), (name, full, ours)
        assert ours == ros_names._rclpy_topic_problem(name, full=full), (name, full)


@pytest.mark.ros
@AGREEMENT
@given(PARAM_NAMES)
def test_parameter_name_rule_agrees_with_rcl_parser(name: str) -> None:
    """The `-p NAME:=VALUE` grammar (lexer quirks included) accepts exactly what rcl does."""
    ours = parameter_name_problem(name) is None
    assert ours == _rclpy_accepts_rule(f"{name}:=1"), name


@pytest.mark.parametrize(
    ("name", "resolved"),
    [
        ("/scan", "/scan"),
        ("scan", "/scan"),
        ("robot/scan", "/robot/scan"),
        ("/robot_1/scan_2", "/robot_1/scan_2"),
        ("_hidden", "/_hidden"),
        ("/" + "a" * 246, "/" + "a" * 246),
    ],
)
def test_good_topics_resolve_to_full_names(name: str, resolved: str) -> None:
    assert resolve_topic(name) == resolved


@pytest.mark.parametrize(
    ("name", "phrase"),
    [
        ("", "must not be empty"),
        ("not a topic", "characters other than alphanumerics"),
        ("/a//b", "must not contain repeated '/' (character 4)"),
        ("a//b", "'/a//b' topic name must not contain repeated '/'"),
        ("/", "must not end with a forward slash"),
        ("scan/", "must not end with a forward slash"),
        ("1scan", "token must not start with a number"),
        ("/robot/2d", "token must not start with a number"),
        ("~/scan", "a private name (~)"),
        ("~", "a private name (~)"),
        ("{node}/scan", "substitutions ({node}, {ns})"),
        ("/scan\x00", "characters other than alphanumerics"),
        ("/scän", "characters other than alphanumerics"),
        ("/scan\n", "characters other than alphanumerics"),
        ("\udce9", "characters other than alphanumerics"),  # undecodable argv byte
        ("/" + "a" * 247, "248 characters, at most 247"),
        ("a" * 247, "248 characters, at most 247"),  # 247 + the leading '/'
    ],
)
def test_bad_topics_are_refused_with_a_reason(name: str, phrase: str) -> None:
    with pytest.raises(InvalidName, match=None) as caught:
        resolve_topic(name)
    assert phrase in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_topic_must_be_text() -> None:
    with pytest.raises(InvalidName, match="must be text, got int"):
        resolve_topic(5)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "rule",
    ["threshold:=0.5", "a.b:=1", "a/b:=x", "node:threshold:=0.3", "lidar_topic:=/robot/scan"],
)
def test_good_parameter_rules(rule: str) -> None:
    assert check_parameter_rule(rule) == rule


@pytest.mark.parametrize(
    ("rule", "phrase"),
    [
        ("threshold", "expected NAME:=VALUE"),
        (":=1", "expected NAME:=VALUE"),
        ("a:=", "expected NAME:=VALUE"),
        ("a b:=1", "expected NAME:=VALUE"),
        ("bad name!:=1", "expected NAME:=VALUE"),
        ("1a:=1", "ROS 2 cannot parse '1a:=1': a parameter name is words"),
        ("a-b:=1", "a parameter name is words"),
        ("__ns:=1", "a parameter name is words"),
        ("a..b:=1", "a parameter name is words"),
        ("/ns/node:a:=1", "a parameter name is words"),
        ("a:=1\x00", "NUL character"),
        (["a:=1"], "expected NAME:=VALUE text, got list"),
    ],
)
def test_bad_parameter_rules(rule: str, phrase: str) -> None:
    with pytest.raises(InvalidName) as caught:
        check_parameter_rule(rule)
    assert phrase in str(caught.value)


@pytest.mark.ros
def test_a_value_rcl_cannot_parse_is_refused_through_rclpy() -> None:
    """The value is YAML that only rcl parses: where rclpy is installed it is asked."""
    with pytest.raises(InvalidName, match=r"ROS 2 cannot parse 'a:=\[unclosed'"):
        check_parameter_rule("a:=[unclosed")


def test_parameter_names_and_targets() -> None:
    assert check_parameter_name("min_dist") == "min_dist"
    with pytest.raises(InvalidName, match="a parameter name is words"):
        check_parameter_name("bad name!")
    with pytest.raises(InvalidName, match="NUL"):
        check_parameter_name("a\x00")
    assert parameter_target("threshold:=1") == ("", "threshold")
    assert parameter_target("my_node:threshold:=1") == ("my_node", "threshold")


def test_the_pure_rules_decide_without_rclpy(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where rclpy is not installed: the same verdicts, from the pure rules alone."""
    for module in [m for m in sys.modules if m == "rclpy" or m.startswith("rclpy.")]:
        monkeypatch.delitem(sys.modules, module)
    monkeypatch.setitem(sys.modules, "rclpy", None)  # import rclpy -> ImportError
    assert resolve_topic("scan") == "/scan"
    with pytest.raises(InvalidName, match="characters other than alphanumerics"):
        resolve_topic("not a topic")
    with pytest.raises(InvalidName, match="repeated '/'"):
        resolve_topic("/a//b")
    with pytest.raises(InvalidName, match="a parameter name is words"):
        check_parameter_rule("1a:=1")
    with pytest.raises(InvalidName, match="a parameter name is words"):
        check_parameter_name("bad name!")
    assert check_parameter_rule("a:=[unclosed") == "a:=[unclosed"  # the value is rcl's to judge
