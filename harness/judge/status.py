"""Read the free-text status a student node publishes (pure).

Students word their status however they like ("Obstacle at 0.84 m, angle
1.57 rad", "d=0.84,a=1.57", "No obstacle"); the oracle needs whether an
obstacle is claimed, its distance and angle, and the printed precision (for
tolerances). The default rules (a structure read by its keys first, then
negative phrases, numbers as written, position unless labelled) are
docs/oracle.md's "Reading the status"; a user regex with named groups
replaces them (``compile_status_pattern``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from harness.errors import ConfigError
from harness.judge.status_numbers import WORD_END, WORD_START, Number, find_numbers
from harness.judge.structured_status import read_structured

__all__ = ["StatusClaim", "compile_status_pattern", "parse_status"]


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
    # A structured status whose keys could not be read: why, and the --status-regex fix.
    unreadable: str | None = None


# Phrases that mean "no obstacle" even when numbers follow.
_NEGATIVE_PHRASES = (
    r"\bno\s+(?:\w+\s+)?(?:obstacles?|objects?|obstructions?|returns?|hits?|detections?"
    r"|readings?|targets?|walls?|echo(?:es)?)\b",  # "no obstacle", "no valid readings"
    WORD_START + r"no[_\-\s]?obstacles?" + WORD_END,  # "NO_OBSTACLE", "no-obstacle"
    r"\bnothing\b",
    r"\bnone\s+(?:detected|found|seen|in\s+range)\b",
    r"\bclear\b",  # "clear", "all clear", "path is clear" (not "clearance")
    r"\b(?:all|path|way|road|route|area|is|are)\s+(?:is\s+)?free\b",
    r"\bobstacle[\s_-]free\b|\bfree\s+(?:path|way|road|route)\b",
    r"\bout\s+of\s+range\b",
    r"\bnot\s+(?:detected|found|present|seen)\b",
    WORD_START + r"obstacles?(?:[\s_]*(?:detected|present|found|ahead))?\s*[:=?]\s*"
    r"(?:false|no|none|n)\b",  # "Obstacle: False", "obstacle_detected=no"
    r"\bbrak\b|\bκανένα\b|\bδεν\s+υπάρχει\b",  # Polish "brak", Greek "none"/"there is no"
)
_NEGATIVE = re.compile("|".join(_NEGATIVE_PHRASES), re.IGNORECASE)
# A negative phrase preceded by one of these is itself negated ("not clear").
_NEGATED = re.compile(r"(?:\bnot|n't|\bnever)\s*$", re.IGNORECASE)


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
    obstacle = said.strip().lower() not in _FALSY if said is not None else distance is not None
    why = f"obstacle group {said!r}" if said is not None else "no distance"
    return _claim(text, obstacle, distance, angle, reason=None if obstacle else why)


def _claim(
    text: str, obstacle: bool, distance: Number | None, angle: Number | None, **more: str | None
) -> StatusClaim:
    """The claim of these numbers: their values and printed precision."""
    return StatusClaim(
        text,
        obstacle,
        distance.value if distance else None,
        angle.value if angle else None,
        distance.decimals if distance else None,
        angle.decimals if angle else None,
        **more,
    )


def parse_status(text: str, pattern: str | re.Pattern[str] | None = None) -> StatusClaim:
    """What `text` claims; `pattern` (a regex with named groups) overrides the default."""
    rx = compile_status_pattern(pattern)
    if rx is not None:
        return _parse_with(rx, text)
    keyed = read_structured(text)
    if keyed is not None:
        said = {"reason": keyed.reason, "unreadable": keyed.unreadable}
        return _claim(text, keyed.obstacle, keyed.distance, keyed.angle, **said)
    negative = _negation(text)
    if negative is not None:
        return StatusClaim(text, False, None, None, None, None, reason=f"says {negative!r}")
    distance, angle = _pick(find_numbers(text))
    if distance is None:
        return StatusClaim(text, False, None, None, None, None, reason="no number")
    return _claim(text, True, distance, angle)


def half_unit(decimals: int | None) -> float:
    """Half a unit in the last printed digit (0 when unknown; a number printed with an
    exponent past a float's range, e.g. '1000E1000', has no finite unit)."""
    if decimals is None:
        return 0.0
    return 0.5 * 10.0 ** (-decimals) if -decimals < 308 else math.inf
