"""Read the free-text status a student node publishes (pure).

Students word their status however they like ("Obstacle at 0.84 m, angle
1.57 rad", "d=0.84,a=1.57", "No obstacle"). The oracle needs three things
from it: is an obstacle claimed, at what distance (metres), at what angle
(radians), and how many decimals were printed (for tolerances).

Default rules, in order:

1. A negative phrase ("no obstacle", "nothing", "clear", "free", "none
   detected", "out of range", "obstacle: false", ...) means no obstacle is
   claimed, whatever numbers follow. A negated negative ("not clear") is
   not one.
2. Numbers are read as written: ``1.2e-1``, ``-0.52``, ``.5``, ``0.842m``,
   ``1.57rad``, Python float reprs, and ``inf``/``nan`` (any case, signed).
   Digits glued to a word or path are not numbers (``LIDAR2``, ``/scan2``,
   ``float32``, ``A1M8``), nor are version-like runs (``1.2.3``).
   Units are never converted: the lab asks for metres and radians.
3. No number at all means no obstacle claimed. ``inf`` and ``nan`` are
   numbers: "Min distance: inf" claims an obstacle at inf m (the lab's own
   pitfall, and wrong).
4. Otherwise the distance is the first number and the angle the second --
   unless labels say otherwise: a unit right after a number (``m``, ``cm``,
   ``mm`` -> distance; ``rad``, ``deg``, ``°`` -> angle; ``s``, ``ms``,
   ``Hz`` -> ignored) or a keyword just before it, since the previous
   number (``distance``/``dist``/``range``/``d=``/``r=`` -> distance;
   ``angle``/``theta``/``bearing``/``heading``/``a=`` -> angle;
   ``index``/``beam``/``i=``/``time``/``t=`` -> ignored). A labelled
   distance or angle wins over position; unlabelled numbers fill the rest
   in order. A gap naming both a distance and an angle word labels nothing.

A user regex with named groups ``distance`` and ``angle`` (and optionally
``obstacle``) replaces all of this; see ``compile_status_pattern``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from harness.errors import ConfigError

__all__ = ["StatusClaim", "Number", "compile_status_pattern", "find_numbers", "parse_status"]


@dataclass(frozen=True)
class StatusClaim:
    """What one status string claims."""

    text: str
    obstacle: bool  # False: "no obstacle claimed"
    distance: float | None
    angle: float | None
    distance_decimals: int | None  # printed precision, for tolerances
    angle_decimals: int | None
    reason: str | None = None  # why no obstacle is claimed, e.g. "says 'no obstacle'"


@dataclass(frozen=True)
class Number:
    """A number found in a status, with where it stands and what labels it."""

    value: float
    decimals: int | None  # digits after the point, less the exponent; None for inf/nan
    start: int
    end: int
    label: str | None  # "distance", "angle", "ignore" or None


# A candidate number; the glue checks happen in find_numbers.
_NUMBER = re.compile(
    r"(?P<sign>[+-]?)"
    r"(?:(?P<inf>inf(?:inity)?)|(?P<nan>nan)"
    r"|(?P<mant>\d+(?:\.(?P<frac>\d*))?|\.(?P<frac2>\d+))(?:[eE](?P<exp>[+-]?\d+))?)",
    re.IGNORECASE,
)

_UNIT = re.compile(
    r"\s?(?P<unit>°|deg(?:rees?)?\b|rad(?:ians?)?\b|m\b|cm\b|mm\b|meters?\b|metres?\b"
    r"|ms\b|s\b|sec(?:onds?)?\b|hz\b)",
    re.IGNORECASE,
)

# Keywords may sit inside identifiers ("min_dist=", "angle_rad:"), so they
# are bounded by letters and digits only, not by "_".
_W = r"(?<![^\W_])"  # not after a letter or digit
_E = r"(?![^\W\d_])"  # not before a letter
_KEYWORDS = {
    "distance": re.compile(
        _W
        + r"(?:distance|dist|range|odleg[łl]o[śs][ćc]|dystans|απόσταση)"
        + _E
        + r"|(?<![\w.])[dr]\s*[:=]",
        re.IGNORECASE,
    ),
    "angle": re.compile(
        _W
        + r"(?:angle|ang|theta|bearing|heading|direction|k[ąa]t|γωνία)"
        + _E
        + r"|θ|(?<![\w.])a\s*[:=]",
        re.IGNORECASE,
    ),
    "ignore": re.compile(
        _W
        + r"(?:index|idx|beam|sample|tick|time|stamp|seq|count)"
        + _E
        + r"|(?<![\w.])[it]\s*[:=]",
        re.IGNORECASE,
    ),
}

# Phrases that mean "no obstacle" even when numbers follow.
_NEGATIVE_PHRASES = (
    r"\bno\s+(?:\w+\s+)?(?:obstacles?|objects?|obstructions?|returns?|hits?|detections?"
    r"|readings?|targets?|walls?|echo(?:es)?)\b",  # "no obstacle", "no valid readings"
    _W + r"no[_\-\s]?obstacles?" + _E,  # "NO_OBSTACLE", "no-obstacle"
    r"\bnothing\b",
    r"\bnone\s+(?:detected|found|seen|in\s+range)\b",
    r"\bclear\b",  # "clear", "all clear", "path is clear" (not "clearance")
    r"\b(?:all|path|way|road|route|area|is|are)\s+(?:is\s+)?free\b",
    r"\bobstacle[\s_-]free\b|\bfree\s+(?:path|way|road|route)\b",
    r"\bout\s+of\s+range\b",
    r"\bnot\s+(?:detected|found|present|seen)\b",
    _W + r"obstacles?(?:[\s_]*(?:detected|present|found|ahead))?\s*[:=?]\s*"
    r"(?:false|no|none|n)\b",  # "Obstacle: False", "obstacle_detected=no"
    r"\bbrak\b|\bκανένα\b|\bδεν\s+υπάρχει\b",  # Polish "brak", Greek "none"/"there is no"
)
_NEGATIVE = re.compile("|".join(_NEGATIVE_PHRASES), re.IGNORECASE)
# A negative phrase preceded by one of these is itself negated ("not clear").
_NEGATED = re.compile(r"(?:\bnot|n't|\bnever)\s*$", re.IGNORECASE)


def _glued(text: str, start: int) -> bool:
    """True when the candidate at `start` continues a word, path or number."""
    if start == 0:
        return False
    prev = text[start - 1]
    if prev.isalnum() or prev in "_/\\":
        return True
    # "1.2.3": a number right after "<digit>." is a version or IP part.
    return prev == "." and start >= 2 and text[start - 2].isdigit()


def _label_after(text: str, end: int) -> str | None:
    m = _UNIT.match(text, end)
    if not m:
        return None
    unit = m.group("unit").lower()
    if unit.startswith(("°", "deg", "rad")):
        return "angle"
    if unit in ("m", "cm", "mm") or unit.startswith("met"):
        return "distance"
    return "ignore"  # s, ms, sec, Hz


def _label_before(gap: str) -> str | None:
    found = [label for label, rx in _KEYWORDS.items() if rx.search(gap)]
    if not found:
        return None
    if len(found) == 1:
        return found[0]
    # Several kinds named since the last number: the nearest one decides,
    # unless it is ambiguous between distance and angle.
    if "distance" in found and "angle" in found:
        return None
    last = max(found, key=lambda label: _last_match_end(_KEYWORDS[label], gap))
    return last


def _last_match_end(rx: re.Pattern[str], text: str) -> int:
    return max((m.end() for m in rx.finditer(text)), default=-1)


def find_numbers(text: str) -> list[Number]:
    """Every number in `text` that stands on its own, with its label."""
    out: list[Number] = []
    pos = 0
    prev_end = 0
    while True:
        m = _NUMBER.search(text, pos)
        if m is None:
            return out
        start = m.start()
        # A sign belongs to the number only if it is not glued ("x-1" is not -1).
        if m.group("sign") and _glued(text, start):
            pos = start + 1
            continue
        if _glued(text, start):
            pos = m.end()
            continue
        word = m.group("inf") or m.group("nan")
        end = m.end()
        if text[end : end + 1] == "." and text[end + 1 : end + 2].isdigit():
            pos = end  # "1.2.3": a version, not a number
            continue
        if word and end < len(text) and (text[end].isalnum() or text[end] == "_"):
            pos = end  # "info", "nanosec", "infinite"
            continue
        if word:
            value = float(m.group("sign") + word.lower().replace("inity", ""))
            decimals: int | None = None
        else:
            frac = m.group("frac") if m.group("frac") is not None else m.group("frac2")
            exp = int(m.group("exp")) if m.group("exp") else 0
            value = float(m.group(0))
            decimals = len(frac or "") - exp
        label = _label_after(text, end) or _label_before(text[prev_end:start])
        out.append(Number(value, decimals, start, end, label))
        pos = prev_end = end


def _pick(numbers: list[Number]) -> tuple[Number | None, Number | None]:
    """Distance and angle: labelled ones first, then unlabelled in order."""
    usable = [n for n in numbers if n.label != "ignore"]
    free = [n for n in usable if n.label is None]
    distance = next((n for n in usable if n.label == "distance"), None)
    if distance is None and free:
        distance = free.pop(0)
    angle = next((n for n in usable if n.label == "angle"), None)
    if angle is None and distance is not None:
        after = [n for n in free if n.start > distance.start]
        angle = next(iter(after or free), None)
    return distance, angle


def _negation(text: str) -> str | None:
    """The first negative phrase that is not itself negated."""
    for m in _NEGATIVE.finditer(text):
        if not _NEGATED.search(text[: m.start()]):
            return m.group(0)
    return None


_FALSY = {"", "0", "false", "no", "n", "none", "off", "clear", "free", "nothing"}


def compile_status_pattern(pattern: str | re.Pattern[str] | None) -> re.Pattern[str] | None:
    """Check a user regex once; ConfigError if it is bad or lacks a distance group."""
    if pattern is None or isinstance(pattern, re.Pattern):
        rx = pattern
    else:
        try:
            rx = re.compile(pattern)
        except re.error as err:
            raise ConfigError(f"status pattern {pattern!r}: bad regex: {err}") from None
    if rx is not None and "distance" not in rx.groupindex:
        raise ConfigError(
            f"status pattern {rx.pattern!r}: needs a named group (?P<distance>...)"
            " (and optionally angle, obstacle)"
        )
    return rx


def _one_number(fragment: str | None) -> Number | None:
    if fragment is None:
        return None
    found = find_numbers(fragment)
    return found[0] if found else None


def _parse_with(rx: re.Pattern[str], text: str) -> StatusClaim:
    m = rx.search(text)
    if m is None:
        return StatusClaim(text, False, None, None, None, None, reason="the pattern does not match")
    groups = m.groupdict()
    distance = _one_number(groups.get("distance"))
    angle = _one_number(groups.get("angle"))
    said = groups.get("obstacle")
    if said is not None:
        obstacle = said.strip().lower() not in _FALSY
    else:
        obstacle = distance is not None
    return StatusClaim(
        text=text,
        obstacle=obstacle,
        distance=distance.value if distance else None,
        angle=angle.value if angle else None,
        distance_decimals=distance.decimals if distance else None,
        angle_decimals=angle.decimals if angle else None,
        reason=None
        if obstacle
        else (f"obstacle group {said!r}" if said is not None else "no distance"),
    )


def parse_status(text: str, pattern: str | re.Pattern[str] | None = None) -> StatusClaim:
    """What `text` claims; `pattern` (a regex with named groups) overrides the default."""
    rx = compile_status_pattern(pattern)
    if rx is not None:
        return _parse_with(rx, text)
    negative = _negation(text)
    if negative is not None:
        return StatusClaim(text, False, None, None, None, None, reason=f"says {negative!r}")
    distance, angle = _pick(find_numbers(text))
    if distance is None:
        return StatusClaim(text, False, None, None, None, None, reason="no number")
    return StatusClaim(
        text=text,
        obstacle=True,
        distance=distance.value,
        angle=angle.value if angle else None,
        distance_decimals=distance.decimals,
        angle_decimals=angle.decimals if angle else None,
    )


def half_unit(decimals: int | None) -> float:
    """Half a unit in the last printed digit (0 when unknown; a number printed with an
    exponent past a float's range, e.g. '1000E1000', has no finite unit)."""
    if decimals is None:
        return 0.0
    return 0.5 * 10.0 ** (-decimals) if -decimals < 308 else math.inf


def is_finite(value: float | None) -> bool:
    return value is not None and math.isfinite(value)
