"""A status printed as a data structure, taken apart into keys and values (pure).

Free-text rules misread JSON and printed dicts (the quotes around
"obstacle" hide its "false"), so a real parser goes first: ``json``; else
Python's (``ast``: walked, never evaluated); else ``key: value`` pairs.
What the keys mean is ``structured_status``'s concern.
"""

from __future__ import annotations

import ast
import enum
import json
import math
import re
import warnings
from dataclasses import dataclass

__all__ = ["Field", "Printed", "Shape", "Structure", "structure_of"]

# Longer texts are not statuses worth a parser's time; the free-text rules read them.
MAX_CHARS = 10_000


@dataclass(frozen=True)
class Printed:
    """A number, with the text it was printed as (its precision counts)."""

    value: float
    text: str


class Shape(enum.Enum):
    """A value this reader does not look into."""

    NESTED = "a nested mapping"  # its items follow as fields one level down
    OTHER = "a list"  # a list, or a mapping nested deeper than one level


Value = bool | str | Printed | Shape | None


@dataclass(frozen=True)
class Field:
    """One value and the keys leading to it: ``("obstacle", "distance")`` one level
    down; ``()`` for an item of a top-level list."""

    key: tuple[str, ...]
    value: Value
    text: str  # the value as written, for messages


@dataclass(frozen=True)
class Structure:
    form: str  # "JSON", "a Python literal" or "key: value pairs"
    fields: tuple[Field, ...]
    keyed: bool  # False: a top-level list or tuple, read by position


class _Mapping(tuple):
    """A mapping's (key, value) pairs in printed order (a list stays a list)."""


class _NotLiteral(Exception):
    pass


# Before the bracket, at most a label ending in ':' or '=' ("Status: {...}").
_BRACED = re.compile(r"\s*(?:[^\W\d][\w .\-/]{0,40}?\s*[:=]\s*)?([\[{(].*[\]})])\s*", re.DOTALL)


def structure_of(text: str) -> Structure | None:
    """The keys and values of `text`, or None when it is not printed as a structure."""
    if len(text) > MAX_CHARS:
        return None
    m = _BRACED.fullmatch(text)
    if m is None:
        pairs = key_value_pairs(text)
        return Structure("key: value pairs", pairs, True) if pairs else None
    body = m.group(1)
    for form, parse in (("JSON", _json), ("a Python literal", _python)):
        tree = parse(body)
        if isinstance(tree, _Mapping):
            return Structure(form, _fields(tree, form), True)
        if isinstance(tree, list | tuple):
            items = [_item(v, _shown(v, form)) for v in tree]
            return Structure(form, tuple(Field((), v, t) for v, t in items), False)
    if body.startswith("{"):  # a YAML flow mapping: {obstacle: false, distance: .inf}
        pairs = key_value_pairs(body[1:-1])
        return Structure("key: value pairs", pairs, True) if pairs else None
    return None


# -- JSON and Python literals ------------------------------------------------------------


def _json(body: str) -> object:
    try:
        return json.loads(
            body,
            parse_float=_printed,
            parse_int=_printed,
            parse_constant=_printed,  # Infinity, -Infinity, NaN
            object_pairs_hook=_Mapping,
        )
    except (ValueError, RecursionError):
        return None


def _printed(text: str) -> Printed:
    return Printed(float(text), text)


_WORDS: dict[str, object] = {"inf": math.inf, "infinity": math.inf, "nan": math.nan}
_WORDS |= {"true": True, "false": False, "null": None, "none": None}
# Calls that only wrap a number as str() and repr() print it: np.float32(0.84), float('inf').
_WRAPPERS = {"float", "int", "double", "float16", "float32", "float64", "float_", "bool_"}


def _python(body: str) -> object:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "invalid escape sequence" and the like
            tree = ast.parse(body, mode="eval").body
        return _literal(tree, body, 0)
    except (SyntaxError, ValueError, OverflowError, RecursionError, MemoryError, _NotLiteral):
        return None


def _literal(node: ast.expr, src: str, depth: int) -> object:
    """The value `node` prints; deeper than one nested mapping, Shape.OTHER."""
    if isinstance(node, ast.Constant):
        v = node.value
        if v is None or isinstance(v, bool | str):
            return v
        if isinstance(v, int | float):
            return Printed(float(v), ast.get_source_segment(src, node) or repr(v))
        return Shape.OTHER
    if isinstance(node, ast.Attribute):  # np.True_ (numpy 2's bools), np.inf, math.nan
        if node.attr in ("True_", "False_"):
            return node.attr == "True_"
        word = _WORDS.get(node.attr.lower())
        return Printed(word, node.attr) if isinstance(word, float) else _not_literal()
    if isinstance(node, ast.Name):  # inf, nan, true, null; else a bare word ({a: yes})
        word = _WORDS.get(node.id.lower(), node.id)
        return Printed(word, node.id) if isinstance(word, float) else word
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        inner = _literal(node.operand, src, depth)
        if isinstance(inner, Printed):
            sign = -1.0 if isinstance(node.op, ast.USub) else 1.0
            return Printed(sign * inner.value, ast.get_source_segment(src, node) or inner.text)
        return _not_literal()
    if isinstance(node, ast.Call) and len(node.args) == 1 and not node.keywords:
        func = node.func
        name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
        if name in _WRAPPERS:
            inner = _literal(node.args[0], src, depth)
            if isinstance(inner, str):  # float('inf')
                try:
                    return Printed(float(inner), inner)
                except ValueError:
                    return _not_literal()
            return inner
        return _not_literal()
    if isinstance(node, ast.Dict):
        if depth > 1:
            return Shape.OTHER
        items = zip(node.keys, node.values, strict=True)
        return _Mapping([(_key(k), _literal(v, src, depth + 1)) for k, v in items])
    if isinstance(node, ast.List | ast.Tuple):
        if depth > 0:
            return Shape.OTHER if node.elts else None
        return [_literal(e, src, depth + 1) for e in node.elts]
    return _not_literal()


def _key(node: ast.expr | None) -> str:
    if isinstance(node, ast.Constant) and isinstance(node.value, str | int | float):
        return str(node.value)
    if isinstance(node, ast.Name):  # {obstacle: false}: a YAML flow mapping's bare keys
        return node.id
    raise _NotLiteral


def _not_literal() -> object:
    raise _NotLiteral


def _item(value: object, text: str) -> tuple[Value, str]:
    """A value as a field holds it: containers are not looked into."""
    if isinstance(value, _Mapping):
        return (Shape.NESTED if value else None), text
    if isinstance(value, list | tuple):
        return (Shape.OTHER if value else None), text
    assert value is None or isinstance(value, bool | str | Printed | Shape)
    return value, text


def _shown(value: object, form: str) -> str:
    if isinstance(value, Printed):
        return value.text
    if isinstance(value, Shape | _Mapping | list | tuple):
        return "{...}" if isinstance(value, _Mapping) else "[...]"
    return json.dumps(value) if form == "JSON" else repr(value)


def _fields(mapping: _Mapping, form: str) -> tuple[Field, ...]:
    out: list[Field] = []
    for key, value in mapping:
        value_, text = _item(value, _shown(value, form))
        out.append(Field((key,), value_, text))
        if value_ is Shape.NESTED:
            for inner, v in value:
                v_, t = _item(v, _shown(v, form))
                out.append(Field((key, inner), Shape.OTHER if v_ is Shape.NESTED else v_, t))
    return tuple(out)


# -- key: value pairs ---------------------------------------------------------------------

# ':' or '=', not '::', '==', '<=', '://'
_SEP = re.compile(r"(?<![:=<>!])[:=](?![:=/])")
_KEY = re.compile(r"(?:-\s+)?[\"']?([^\W\d][\w.\-]*(?:[ \t]+[^\W\d][\w.\-]*){0,2})[\"']?")
_UNITS = r"°|deg(?:rees?)?|rad(?:ians?)?|m|cm|mm|meters?|metres?|s|ms|sec|hz"
# A value: a quoted string, a word or number (with its unit), or an empty [] or {}.
_SCALAR = re.compile(
    rf"(?:\"[^\"]*\"|'[^']*'|[\w.+\-/%~°]+(?:[ \t]*(?:{_UNITS}))?|\[\]|\{{\}})", re.IGNORECASE
)
_UNIT_WORD = re.compile(rf"(?:{_UNITS})", re.IGNORECASE)
_DELIMS = re.compile(r"[,;|]")
_YAML_NUMBER = re.compile(r"([+-]?)\.(inf|nan)", re.IGNORECASE)
_PLAIN_NUMBER = re.compile(r"[+-]?(?:(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)")
_NULLS = {"", "~", "null", "none", "nil"}


def key_value_pairs(text: str) -> tuple[Field, ...]:
    """`text` as ``key: value`` pairs (on lines, or separated by ',', ';', '|' or
    spaces; a key with an empty value and indented lines under it holds those), or
    () when any part of it is something else."""
    out: list[Field] = []
    parent: tuple[int, int] | None = None  # the empty-valued field's place, its indent
    for line in text.splitlines():
        if not line.strip():
            continue
        indent = len(line) - len(line.lstrip())
        pairs = _line_pairs(line.strip())
        if pairs is None:
            return ()
        if parent is not None and indent > parent[1]:
            key = out[parent[0]].key
            out[parent[0]] = Field(key, Shape.NESTED, "{...}")
            out += [Field((*key, *f.key), f.value, f.text) for f in pairs]
            continue
        parent = None
        out += pairs
        last = pairs[-1]
        if last.value is None and last.text == "":
            parent = (len(out) - 1, indent)
    return tuple(out)


def _line_pairs(line: str) -> list[Field] | None:
    seps = list(_SEP.finditer(line))
    if not seps:
        return None
    key = _KEY.fullmatch(line[: seps[0].start()].strip())
    if key is None:
        return None
    out: list[Field] = []
    name = key.group(1)
    for here, after in zip(seps, [*seps[1:], None], strict=True):
        segment = line[here.end() : after.start() if after else len(line)]
        if after is None:
            value, next_key = segment, ""
        else:
            split = _split(segment)
            if split is None:
                return None
            value, next_key = split
        value = value.strip().rstrip(",;|").strip()
        if value and not _SCALAR.fullmatch(value):
            return None
        out.append(Field((name,), _scalar(value), value))
        if after is not None:
            m = _KEY.fullmatch(next_key.strip())
            if m is None:
                return None
            name = m.group(1)
    return out


def _split(segment: str) -> tuple[str, str] | None:
    """One value and the next key, from the text between two separators."""
    delims = list(_DELIMS.finditer(segment))
    if delims:
        cut = delims[-1]
        return segment[: cut.start()], segment[cut.end() :]
    words = segment.split()
    if len(words) < 2:
        return None
    take = 2 if len(words) > 2 and _UNIT_WORD.fullmatch(words[1]) else 1
    return " ".join(words[:take]), " ".join(words[take:])


def _scalar(value: str) -> Value:
    """A YAML-like scalar: null, a bool word, a number, else the text."""
    bare = value.strip("\"'") if value[:1] in "\"'" and value[-1:] == value[:1] else value
    low = bare.lower()
    if low in _NULLS:
        return None
    if low in ("true", "yes", "on"):
        return True
    if low in ("false", "no", "off"):
        return False
    yaml = _YAML_NUMBER.fullmatch(bare)
    if yaml:
        return Printed(float(yaml.group(1) + yaml.group(2)), bare)
    if _PLAIN_NUMBER.fullmatch(bare):
        return Printed(float(bare), bare)
    return bare
