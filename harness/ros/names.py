"""ROS 2 names the user gives the harness: topic names and parameter names.

A name ROS 2 refuses would fail deep in rclpy or in the node (which never comes up);
checked here it is one usage line. The rules are ROS 2's own (rcl's
``rcl_validate_topic_name``, rmw's ``rmw_validate_full_topic_name``, rcl's ``-p
NAME:=VALUE`` lexer), copied in pure Python for machines without rclpy; where rclpy is
installed it is asked too, imported only when a name is checked
(tests/test_ros_names.py proves both agree). Topics: absolute or relative (resolved
against the root, where the harness's node lives); private (``~/scan``) and
substituted (``{node}/scan``) names are refused, as they resolve against the node that
uses them. Parameters: ``node:`` optional, then tokens of letters, digits and ``_``
joined by ``.`` or ``/``."""

from __future__ import annotations

import re
from functools import partial
from typing import Any

from harness.safe_text import shown

__all__ = [
    "MAX_TOPIC_LENGTH",
    "InvalidName",
    "check_parameter_name",
    "check_parameter_rule",
    "full_topic_name_problem",
    "parameter_name_problem",
    "parameter_target",
    "resolve_topic",
    "SHOWN_LIMIT",
    "shown_name",
    "topic_name_problem",
]

#: rmw's RMW_TOPIC_MAX_NAME_LENGTH (255 - 8: room for the DDS "rt/" prefix and more).
MAX_TOPIC_LENGTH = 247
_ALNUM = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789")
_DIGITS = frozenset("0123456789")
SHOWN_LIMIT = 60  # characters of a refused name shown in the message
#: A name as a message shows it: quoted (spaces and '' visible), cut past SHOWN_LIMIT.
shown_name = partial(shown, limit=SHOWN_LIMIT, quoted=True)


class InvalidName(ValueError):
    """A name ROS 2 (or the harness) refuses; the message is one line without the option."""


# -- topic names: rcl_validate_topic_name, rmw_validate_full_topic_name -------


_SUBSTITUTION_CHARACTERS = (
    "substitution name must not contain characters other than alphanumerics or '_'"
)
_TOPIC_CHARACTERS = (
    "topic name must not contain characters other than alphanumerics, '_', '~', '{', or '}'"
)


def topic_name_problem(name: str) -> tuple[str, int] | None:
    """rcl_validate_topic_name: (reason, index) when `name` is not a topic name, else None;
    relative, private and substituted names pass unexpanded (see full_topic_name_problem)."""
    if not name:
        return "topic name must not be empty string", 0
    if name[0] in _DIGITS:
        return "topic name token must not start with a number", 0
    if name[-1] == "/":
        return "topic name must not end with a forward slash", len(name) - 1
    in_braces, opened = False, 0
    for i, c in enumerate(name):
        if c in _ALNUM:
            if c in _DIGITS and in_braces and i - 1 == opened:
                return "substitution name must not start with a number", i
        elif c == "_" or (c == "/" and not in_braces):
            pass
        elif c == "~":
            if i != 0:
                return "topic name must not have tilde '~' unless it is the first character", i
        elif c == "{" and not in_braces:
            opened, in_braces = i, True
        elif c == "}":
            if not in_braces:
                return "topic name must not have unmatched (unbalanced) curly braces '{}'", i
            in_braces = False
        elif in_braces:  # a '/' or '{' inside braces too
            return _SUBSTITUTION_CHARACTERS, i
        else:
            return _TOPIC_CHARACTERS, i
    if in_braces:
        return "topic name must not have unmatched (unbalanced) curly braces '{}'", opened
    for i in range(len(name) - 1):
        if name[i] == "/":
            if name[i + 1] in _DIGITS:
                return "topic name token must not start with a number", i + 1
        elif i == 1 and name[0] == "~":  # rcl's own check, quirks included: '~a' passes
            return (
                "topic name must not have a tilde '~' that is not followed by a forward slash '/'",
                1,
            )
    return None


def full_topic_name_problem(name: str) -> tuple[str, int] | None:
    """rmw_validate_full_topic_name: (reason, index) unless `name` is a fully qualified name."""
    if not name:
        return "topic name must not be empty", 0
    if name[0] != "/":
        return "topic name must be absolute, it must lead with a '/'", 0
    if name[-1] == "/":
        return "topic name must not end with a '/'", len(name) - 1
    for i, c in enumerate(name):
        if c not in _ALNUM and c not in "_/":
            return (
                "topic name must not contain characters other than alphanumerics, '_', or '/'",
                i,
            )
    for i in range(len(name) - 1):
        if name[i] == "/":
            if name[i + 1] == "/":
                return "topic name must not contain repeated '/'", i + 1
            if name[i + 1] in _DIGITS:
                return "topic name must not have a token that starts with a number", i + 1
    if len(name) > MAX_TOPIC_LENGTH:
        return "topic length should not exceed '255U - 8U'", MAX_TOPIC_LENGTH - 1
    return None


def _rclpy_topic_problem(name: str, *, full: bool) -> tuple[str, int] | None:
    """rclpy's verdict on `name` (None where rclpy is not installed, or it accepts)."""
    try:
        from rclpy.exceptions import NameValidationException

        if full:
            from rclpy.validate_full_topic_name import validate_full_topic_name as validate
        else:
            from rclpy.validate_topic_name import validate_topic_name as validate
    except Exception:  # noqa: BLE001 - not installed, or broken: the pure rules decide
        return None
    try:
        validate(name)
    except NameValidationException as err:
        # "Invalid topic name: REASON:\n  'name'\n   ^" -> REASON, and the caret's index
        lines = str(err).splitlines()
        reason = lines[0].split(": ", 1)[-1].rstrip(":")
        index = len(lines[2]) - 4 if len(lines) > 2 else 0
        return reason, index
    return None


def _topic_problem(name: str, *, full: bool) -> tuple[str, int] | None:
    """The pure rules first (they also keep NUL and non-ASCII text away from C), then rclpy."""
    problem = full_topic_name_problem(name) if full else topic_name_problem(name)
    return problem or _rclpy_topic_problem(name, full=full)


def resolve_topic(name: str) -> str:
    """`name` as the fully qualified topic the harness uses (``scan`` -> ``/scan``);
    InvalidName says why it cannot be (private names and substitutions are refused)."""
    if not isinstance(name, str):
        raise InvalidName(f"a topic name must be text, got {type(name).__name__}")
    problem = _topic_problem(name, full=False)
    if problem is not None:
        reason, index = problem
        raise InvalidName(f"{reason} (character {index + 1})" if name else reason)
    if name.startswith("~"):
        raise InvalidName(
            "a private name (~) resolves against the name of the node using it, and the "
            "harness's node is not the node under test: give the full name, e.g. /my_node/scan"
        )
    if "{" in name:
        raise InvalidName(
            "substitutions ({node}, {ns}) resolve against the node using them, and the "
            "harness's node is not the node under test: give the full name"
        )
    full = name if name.startswith("/") else "/" + name
    problem = _topic_problem(full, full=True)
    if problem is not None:
        reason, index = problem
        if index >= MAX_TOPIC_LENGTH - 1 and "length" in reason:
            raise InvalidName(f"longer than ROS 2 takes: {len(full)} characters, at most 247")
        where = f"{full!r} " if full != name else ""
        raise InvalidName(f"{where}{reason} (character {index + 1})")
    return full


# -- parameter names: rcl's `--ros-args -p NAME:=VALUE` parser ----------------

# rcl's lexer (rcl/src/rcl/lexer.c), reduced to what can appear left of ':=':
# a TOKEN starts with a letter, or with one '_' not followed by another
# (two start __ns, __node, __name); an '_' inside must be followed by a
# letter or digit to continue the token, else the token ends after it.
_TOKEN = re.compile(
    r"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*_?|_(?!_)(?:[A-Za-z0-9]+(?:_[A-Za-z0-9]+)*_?)?"
)
_URLS = ("rostopic://", "rosservice://")
TOKEN, SLASH, DOT, COLON, OTHER, END = "token", "/", ".", ":", "other", "end"


def _lexemes(name: str) -> list[str]:
    """The kinds of lexeme rcl's lexer finds in `name` (which holds no ':=')."""
    kinds: list[str] = []
    i = 0
    while i < len(name):
        if name.startswith(_URLS, i):
            return [*kinds, OTHER]
        match = _TOKEN.match(name, i)
        if match is not None:
            kinds.append(TOKEN)
            i = match.end()
            continue
        c = name[i]
        if c in "/.:":
            kinds.append({"/": SLASH, ".": DOT, ":": COLON}[c])
            i += 1
            continue
        return [*kinds, OTHER]  # digits first, __, ~, *, \, spaces, anything else
    return [*kinds, END]


def parameter_name_problem(name: str) -> str | None:
    """Why rcl's ``-p NAME:=VALUE`` parser refuses `name` (with an optional ``node:`` prefix)."""
    if not name:
        return "the name is empty"
    kinds = _lexemes(name)
    i = 2 if kinds[:2] == [TOKEN, COLON] else 0  # node_name: prefix
    while True:
        if kinds[i] not in (TOKEN, SLASH):
            break
        while kinds[i] in (TOKEN, SLASH):
            i += 1
        if kinds[i] == END:
            return None
        if kinds[i] != DOT:
            break
        i += 1
    return (
        "a parameter name is words of letters, digits and '_' (not starting with a digit "
        "or '__') joined by '.' or '/', after an optional 'node_name:'"
    )


def _rclpy_rule_problem(rule: str) -> str | None:
    """Why rcl (through rclpy) cannot parse ``-p RULE``; None where it can or rclpy is missing."""
    try:
        from rclpy.utilities import remove_ros_args
    except Exception:  # noqa: BLE001 - not installed, or broken: the pure rules decide
        return None
    try:
        remove_ros_args(["fossbot-hil", "--ros-args", "-p", rule])
    except Exception as err:  # noqa: BLE001 - rclpy's RCLInvalidROSArgsError and kin
        reason = str(err).split("Error: ", 1)[-1].split(", at ", 1)[0]
        return " ".join(reason.split())[:150]
    return None


def check_parameter_rule(rule: Any) -> str:
    """A ``NAME:=VALUE`` item ROS 2 can parse; returns it, else InvalidName says why."""
    if not isinstance(rule, str):
        raise InvalidName(f"expected NAME:=VALUE text, got {type(rule).__name__}")
    name, sep, value = rule.partition(":=")
    text = shown_name(rule)
    if not sep or not name or not value or any(c.isspace() for c in name):
        raise InvalidName(f"expected NAME:=VALUE, got {text}")
    if "\0" in rule:
        raise InvalidName(f"ROS 2 cannot parse {text}: it holds a NUL character")
    problem = parameter_name_problem(name)
    if problem is not None:
        raise InvalidName(f"ROS 2 cannot parse {text}: {problem}")
    problem = _rclpy_rule_problem(rule)
    if problem is not None:
        raise InvalidName(f"ROS 2 cannot parse {text}: {problem}")
    return rule


def check_parameter_name(name: Any) -> str:
    """A parameter name ROS 2 takes in ``-p NAME:=1.0``; returns it, else InvalidName."""
    if not isinstance(name, str):
        raise InvalidName(f"a parameter name must be text, got {type(name).__name__}")
    if "\0" in name:
        problem: str | None = "it holds a NUL character"
    else:
        problem = parameter_name_problem(name) or _rclpy_rule_problem(f"{name}:=1.0")
    if problem is not None:
        raise InvalidName(problem)
    return name


def parameter_target(rule: str) -> tuple[str, str]:
    """(node, name) a checked ``[node:]name:=value`` item sets; node '' means every node."""
    name = rule.partition(":=")[0]
    node, colon, rest = name.partition(":")
    return (node, rest) if colon else ("", name)
