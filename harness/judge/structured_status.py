"""What a status printed as JSON, a Python dict or ``key: value`` lines claims (pure).

Keys are explicit, so they beat position: ``obstacle: false`` claims no
obstacle whatever distance follows (json's ``Infinity`` included), and
numbers under keys that say nothing fill the distance and angle in order.
A structure none of whose keys mean anything is left to the free-text rules;
a flag or value that cannot be read makes the status unreadable, with a
``--status-regex`` that reads it the way its keys suggest. Which key means
what: docs/oracle.md, "Structured statuses".
"""

from __future__ import annotations

import math
import re
import shlex
from collections.abc import Callable
from dataclasses import dataclass

from harness.judge.status_numbers import Number, find_numbers
from harness.judge.structured_text import Field, Printed, Shape, Structure, structure_of
from harness.option_names import named

__all__ = ["KeyedClaim", "read_structured"]


@dataclass(frozen=True)
class KeyedClaim:
    """What a structured status claims (``status`` makes it a StatusClaim)."""

    obstacle: bool
    distance: Number | None
    angle: Number | None
    reason: str | None  # why no obstacle is claimed
    unreadable: str | None  # what could not be read, and the fix


_IGNORE = {
    "index", "idx", "beam", "beams", "sample", "samples", "tick", "time", "stamp",
    "timestamp", "seq", "count", "i", "t", "n", "num", "max", "maximum", "threshold",
    "thresh", "limit", "warning", "warn", "alarm", "increment", "hz", "rate", "frequency",
    "id", "frame", "step", "total", "points", "readings", "sec", "secs",
    "seconds", "ms",
}  # fmt: skip
_ANGLE = {
    "angle", "angles", "ang", "theta", "bearing", "heading", "direction", "dir", "yaw",
    "azimuth", "phi", "rad", "rads", "radian", "radians", "deg", "degree", "degrees", "a",
    "θ", "kąt", "kat", "γωνία",
}  # fmt: skip
_DISTANCE = {
    "distance", "distances", "dist", "range", "min", "minimum", "nearest", "closest", "d",
    "r", "m", "meters", "metres", "cm", "mm", "odległość", "odleglosc", "dystans",
    "απόσταση",
}  # fmt: skip
# Flag keys. A number under these ("noun") is the obstacle's distance ({"obstacle": 0.84})
_FLAG_NOUNS = {"obstacle", "obstacles", "object", "objects", "hit"}
# ... under these ("verb") it is a C-style bool ({"detected": 1}).
_FLAG_VERBS = {"detected", "detection", "found", "present", "blocked", "obstructed"}
# ... and these ("clear") say the way is clear: true is no obstacle ({"out_of_range": true}).
_CLEAR = {"clear", "free"}
_CLEAR_PHRASES = r"\b(?:out of range|no obstacles?|nothing)\b"
_TRUE = {"true", "yes", "y", "on", "1", "t", "detected", "found", "present", "blocked", "ahead"}
_FALSE = {
    "false", "no", "n", "off", "0", "f", "none", "null", "nil", "~", "nothing", "clear",
    "free", "absent", "", "n/a", "na", "[]", "{}",
}  # fmt: skip


def _words(key: str) -> list[str]:
    """'minDistance' -> ['min', 'distance']; 'angle_rad' -> ['angle', 'rad']."""
    split = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", key)
    return [w for w in re.split(r"[\W_]+", split.lower()) if w]


def _role(key: str) -> str | None:
    words = set(_words(key))
    joined = " ".join(_words(key))
    if not words & _IGNORE and (words & _CLEAR or re.search(_CLEAR_PHRASES, joined)):
        return "clear"
    for role, names in (
        ("ignore", _IGNORE),
        ("angle", _ANGLE),
        ("distance", _DISTANCE),
        ("noun", _FLAG_NOUNS),
        ("verb", _FLAG_VERBS),
    ):
        if words & names:
            return role
    return None


@dataclass(frozen=True)
class _Keyed:
    field: Field
    role: str | None  # its own key's, else (one level down) the outer key's
    own: bool

    @property
    def name(self) -> str:
        return ".".join(self.field.key)

    @property
    def said(self) -> str:
        return f"{self.name}: {self.field.text}"

    @property
    def said_as(self) -> str:
        """'obstacle' is 'yes-ish'; 'obstacle' is "maybe" (a string quoted as printed)."""
        text = self.field.text
        shown = text if text[:1] in ("'", '"') else repr(text)
        return f"{self.name!r} is {shown}"


def _keyed(field: Field) -> _Keyed:
    own = _role(field.key[-1])
    if own is None and len(field.key) > 1:
        return _keyed_as(field, _role(field.key[0]), False)
    return _keyed_as(field, own, True)


def _keyed_as(field: Field, role: str | None, own: bool) -> _Keyed:
    if role == "clear" and _numeric(field.value):
        role = None  # "Free space ahead: 1.2 m" says a number, not that the way is clear
    return _Keyed(field, role, own)


def _numeric(value: object) -> bool:
    return isinstance(value, Printed) or (isinstance(value, str) and bool(find_numbers(value)))


def read_structured(text: str) -> KeyedClaim | None:
    """What `text` claims by its keys; None when it is no structure, or one none of
    whose keys say what it claims (the free-text rules read it then)."""
    structure = structure_of(text)
    if structure is None:
        return None
    if not structure.keyed:
        return _by_position(structure)
    return _by_keys([_keyed(f) for f in structure.fields])


class _Unreadable(Exception):
    pass


def _by_keys(keyed: list[_Keyed]) -> KeyedClaim | None:
    if all(k.role is None for k in keyed):
        return None
    # Own keys before a nested value's outer key; a flag key may hold the distance. A
    # flag holding a mapping or list is none: what is in it says ({"obstacle": {...}}).
    ordered = sorted(keyed, key=lambda k: not k.own)
    flags = [k for k in ordered if k.role in ("noun", "verb", "clear") and not _is_shape(k)]
    dist_keys = [k for k in ordered if k.role == "distance" and not _is_bool(k)]
    angle_keys = [k for k in ordered if k.role == "angle" and not _is_bool(k)]
    flags += [k for k in ordered if k.role in ("distance", "angle") and _is_bool(k)]
    free = [k for k in keyed if k.role is None and _numeric(k.field.value)]
    try:
        flag, flag_distance = _flag(flags, has_distance=bool(dist_keys))
        if flag is not None and flag[1] is False:  # whatever the other keys hold
            return KeyedClaim(False, None, None, f"says {flag[0].said}", None)
        if flag_distance is not None:
            dist_keys.insert(0, flag_distance)
        distance, dist_from = _number_of(dist_keys, free, "distance")
        angle, _ = _number_of(angle_keys, free, "angle")
    except _Unreadable as err:
        return KeyedClaim(False, None, None, str(err), _unreadable(keyed, str(err)))
    if flag is None and distance is None:
        why = f"says {dist_from.said}" if dist_from is not None else "no distance"
        return KeyedClaim(False, None, None, why, None)
    return KeyedClaim(True, distance, angle, None, None)


def _is_bool(k: _Keyed) -> bool:
    return isinstance(k.field.value, bool)


def _is_shape(k: _Keyed) -> bool:
    return isinstance(k.field.value, Shape)


def _flag(
    flags: list[_Keyed], has_distance: bool
) -> tuple[tuple[_Keyed, bool] | None, _Keyed | None]:
    """The first readable flag's answer, or the flag key that holds the distance
    instead; unreadable when flag keys hold only values that are neither."""
    unreadable: _Keyed | None = None
    for k in flags:
        answer = _answer(k, has_distance)
        if answer == "distance":
            return None, k  # {"obstacle": 0.84}, obstacle: 0.84 m
        if isinstance(answer, bool):
            return (k, answer), None
        if answer == "unreadable":
            unreadable = unreadable or k
    if unreadable is not None:
        raise _Unreadable(f"its {unreadable.said_as}, neither true nor false")
    return None, None


def _answer(k: _Keyed, has_distance: bool) -> bool | str | None:
    """Is an obstacle claimed by this flag: a bool, "distance" (it holds the
    distance), "unreadable", or None (a null "clear": no word either way)."""
    v = k.field.value
    if v is None:
        return None if k.role == "clear" else False
    if isinstance(v, bool):
        yes = v
    elif isinstance(v, Printed):
        if k.role == "noun" and not (has_distance and k.field.text in ("0", "1")):
            return "distance"
        yes = v.value != 0
    else:
        assert isinstance(v, str)
        low = v.strip().lower()
        if low in _TRUE | _FALSE:
            yes = low in _TRUE
        elif k.role == "noun" and find_numbers(v):
            return "distance"
        else:
            return "unreadable"
    return not yes if k.role == "clear" else yes


def _number_of(
    keys: list[_Keyed], free: list[_Keyed], what: str
) -> tuple[Number | None, _Keyed | None]:
    """The first readable key's number (None for null), else the first number whose
    key says nothing; and the field it came from. Unreadable when keys name it and
    none of their values is a number or null."""
    unreadable: _Keyed | None = None
    for k in keys:
        v = k.field.value
        if isinstance(v, Shape):
            continue  # the nested items say it
        if v is None:
            return None, k
        if isinstance(v, Printed):
            return _number(v.value, v.text, what), k
        assert isinstance(v, str)
        found = find_numbers(v)
        if found:
            return Number(found[0].value, found[0].decimals, 0, 0, what), k
        if v.strip().lower() in _FALSE:
            return None, k
        unreadable = unreadable or k
    if unreadable is not None:
        raise _Unreadable(f"its {unreadable.said_as}, not a number")
    if free:
        v = free.pop(0).field.value
        if isinstance(v, Printed):
            return _number(v.value, v.text, what), None
        first = find_numbers(str(v))[0]
        return Number(first.value, first.decimals, 0, 0, what), None
    return None, None


def _number(value: float, text: str, what: str) -> Number:
    """`value` with the precision `text` printed it at."""
    found = find_numbers(text)
    decimals = found[0].decimals if len(found) == 1 else None
    if not math.isfinite(value):
        decimals = None
    return Number(value, decimals, 0, 0, what)


def _by_position(structure: Structure) -> KeyedClaim | None:
    """A printed list or tuple: a bool in it is the flag, its numbers (or None) in
    order the distance and the angle; without a bool the free-text rules read it."""
    flag = next((f for f in structure.fields if isinstance(f.value, bool)), None)
    if flag is None:
        return None
    if flag.value is False:
        return KeyedClaim(False, None, None, f"says {flag.text}", None)
    slots = [f.value for f in structure.fields if f.value is None or isinstance(f.value, Printed)]
    d, a = (
        _number(v.value, v.text, w) if isinstance(v, Printed) else None
        for v, w in zip((*slots, None, None)[:2], ("distance", "angle"), strict=True)
    )
    return KeyedClaim(True, d, a, None, None)


def _unreadable(keyed: list[_Keyed], why: str) -> str:
    """`why`, and a --status-regex that reads the status the way its keys suggest."""
    found: list[tuple[int, str, str]] = []
    for group, roles in (
        ("obstacle", ("noun", "verb")),
        ("distance", ("distance",)),
        ("angle", ("angle",)),
    ):
        at = _first(keyed, lambda k, r=roles: k.own and k.role in r and not _is_shape(k))
        if at is None and group == "distance":  # the first number whose key says nothing
            at = _first(keyed, lambda k: k.role is None and isinstance(k.field.value, Printed))
        if at is not None:
            found.append((at, group, keyed[at].field.key[-1]))
    if not any(group == "distance" for _, group, _ in found):
        return (
            f"{why}; a {named('status_regex')} with named groups (?P<distance>...) and optionally"
            " (?P<angle>...) and (?P<obstacle>...) reads a status written another way"
            " (docs/oracle.md)"
        )
    pieces = [_piece(key, group) for _, group, key in sorted(found)]
    rx = "(?is)" + pieces[0] + "".join(f"(?:.*?{p})?" for p in pieces[1:])
    option = named("status_regex")
    return f"{why}; if the node is right, say how to read it: {option} {shlex.quote(rx)}"


def _first(keyed: list[_Keyed], wanted: Callable[[_Keyed], bool]) -> int | None:
    return next((i for i, k in enumerate(keyed) if wanted(k)), None)


def _piece(key: str, group: str) -> str:
    """`key`, then what separates it from its value, then the value as `group`."""
    name = r"\s+".join(re.escape(w) for w in key.split())
    start = r"\b" if re.match(r"\w", key) else r"(?<!\w)"
    return rf"{start}{name}\W+(?P<{group}>[\w.+-]*)"
