"""Numbers in a student's status text, and what labels each (pure).

Every number that stands on its own (not the "2" of "LIDAR2", nor "1.2.3"),
its printed precision, and whether a unit after it or a keyword before it
makes it a distance, an angle, or something to ignore.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["KEYWORDS", "WORD_END", "WORD_START", "Number", "find_numbers"]


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
WORD_START = r"(?<![^\W_])"  # not after a letter or digit
WORD_END = r"(?![^\W\d_])"  # not before a letter
KEYWORDS = {
    "distance": re.compile(
        WORD_START
        + r"(?:distance|dist|range|odleg[łl]o[śs][ćc]|dystans|απόσταση)"
        + WORD_END
        + r"|(?<![\w.])[dr]\s*[:=]",
        re.IGNORECASE,
    ),
    "angle": re.compile(
        WORD_START
        + r"(?:angle|ang|theta|bearing|heading|direction|k[ąa]t|γωνία)"
        + WORD_END
        + r"|θ|(?<![\w.])a\s*[:=]",
        re.IGNORECASE,
    ),
    "ignore": re.compile(
        WORD_START
        + r"(?:index|idx|beam|sample|tick|time|stamp|seq|count)"
        + WORD_END
        + r"|(?<![\w.])[it]\s*[:=]",
        re.IGNORECASE,
    ),
}


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
    found = [label for label, rx in KEYWORDS.items() if rx.search(gap)]
    if not found:
        return None
    if len(found) == 1:
        return found[0]
    # Several kinds named since the last number: the nearest one decides,
    # unless it is ambiguous between distance and angle.
    if "distance" in found and "angle" in found:
        return None
    return max(found, key=lambda label: _last_match_end(KEYWORDS[label], gap))


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
