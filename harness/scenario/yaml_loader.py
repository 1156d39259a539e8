"""Reading scenario YAML, bounded: the YAML 1.2 core schema only, no surprises."""

from __future__ import annotations

import math
import re
from typing import Any

import yaml

from harness.scenario.limits import MAX_YAML_DEPTH, MAX_YAML_NODES, MAX_YAML_SCALAR

# -- reading YAML, bounded ----------------------------------------------------


# YAML 1.2 core schema scalars. PyYAML implements YAML 1.1, which also reads
# `1_000` and `1:20` (= 80) as integers, `010` as octal 8, `0b11`, `yes`/`no`/
# `on`/`off` as booleans and `2024-01-01` as a date, but `1e-3` as text. Here
# those are text (a numeric field then refuses them), except a leading zero,
# which YAML 1.1 and 1.2 read differently (8 or 10): that is text too.
_BOOL_1_2 = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
INT_1_2 = re.compile(r"^(?:[-+]?(?:0|[1-9][0-9]*)|0o[0-7]+|0x[0-9a-fA-F]+)$")
FLOAT_1_2 = re.compile(
    r"^(?:[-+]?(?:\.[0-9]+|[0-9]+\.[0-9]*|[0-9]+(?=[eE]))(?:[eE][-+]?[0-9]+)?"
    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
)
_YAML = "tag:yaml.org,2002:"
_CORE_TAGS = {f"{_YAML}{kind}" for kind in ("null", "bool", "int", "float", "str", "seq", "map")}


class _ScenarioLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing what no scenario needs and a hostile file uses.

    Duplicate keys (PyYAML silently keeps the last), keys that are not text,
    nesting deeper than MAX_YAML_DEPTH (PyYAML recurses: a deep file is a
    RecursionError), and, checked on the composed document, alias "bombs":
    a few lines whose aliases expand to billions of values.
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: yaml.Node | None, index: object) -> yaml.Node | None:
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                mark = self.peek_event().start_mark
                raise yaml.composer.ComposerError(
                    None, None, f"nested deeper than {MAX_YAML_DEPTH} levels", mark
                )
            return super().compose_node(parent, index)  # type: ignore[misc]
        finally:
            self._depth -= 1

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[str, yaml.Mark] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue  # `<<: *defaults` keys may be overridden: not duplicates
            key = self.construct_object(key_node) if isinstance(key_node, yaml.ScalarNode) else None
            if not isinstance(key, str):
                shown = key_node.value if isinstance(key_node, yaml.ScalarNode) else "a collection"
                raise yaml.constructor.ConstructorError(
                    None, None, f"keys must be text, got {str(shown)[:40]!r}", key_node.start_mark
                )
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"duplicate key {key[:40]!r} (first at line {seen[key].line + 1})",
                    key_node.start_mark,
                )
            seen[key] = key_node.start_mark
        return super().construct_mapping(node, deep)


def _core_scalar(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> bool | int | float:
    """A bool, int or float as YAML 1.2 writes it, also under an explicit `!!int` etc. tag."""
    kind = node.tag.removeprefix(_YAML)
    pattern = {"bool": _BOOL_1_2, "int": INT_1_2, "float": FLOAT_1_2}[kind]
    text = str(loader.construct_scalar(node))
    if not pattern.match(text) and not (kind == "float" and INT_1_2.match(text)):
        raise yaml.constructor.ConstructorError(
            None, None, f"{text[:40]!r} is not a YAML 1.2 {kind}", node.start_mark
        )
    if kind == "bool":
        return text.lower() == "true"
    if kind == "int" or (kind == "float" and INT_1_2.match(text)):
        value = int(text, 0)
        if kind == "int":
            return value
        return float(value) if abs(value) < 2**1024 else math.copysign(math.inf, value)
    special = text.lower().lstrip("+")
    if special in (".inf", "-.inf", ".nan"):
        return float(special.replace(".", ""))
    return float(text)


# Only the YAML 1.2 core schema: implicit types as it resolves them, and no
# other tags (`!!binary`, `!!set` in an arbitrary order, `!!timestamp`, ...).
_ScenarioLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag in (f"{_YAML}null", f"{_YAML}merge")]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
for _tag, _pattern, _first in (
    ("bool", _BOOL_1_2, "tTfF"),
    ("int", INT_1_2, "-+0123456789"),
    ("float", FLOAT_1_2, "-+0123456789."),
):
    _ScenarioLoader.add_implicit_resolver(f"{_YAML}{_tag}", _pattern, list(_first))
_ScenarioLoader.yaml_constructors = {
    tag: construct
    for tag, construct in yaml.SafeLoader.yaml_constructors.items()
    if tag in _CORE_TAGS or tag is None
}
for _tag in ("bool", "int", "float"):
    _ScenarioLoader.add_constructor(f"{_YAML}{_tag}", _core_scalar)


def _check_expanded(root: yaml.Node) -> None:
    """Every value counted as often as aliases repeat it: bounded size, depth, no cycles."""
    sizes: dict[int, tuple[int, int]] = {}  # id(node) -> (values, depth) below and with it
    active: set[int] = set()

    def refused(problem: str, node: yaml.Node) -> yaml.composer.ComposerError:
        return yaml.composer.ComposerError(None, None, problem, node.start_mark)

    def visit(node: yaml.Node) -> tuple[int, int]:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in active:
            raise refused("an alias refers to the value it is inside", node)
        if isinstance(node, yaml.ScalarNode):
            if len(node.value) > MAX_YAML_SCALAR:
                raise refused(f"a value longer than {MAX_YAML_SCALAR} characters", node)
            sizes[key] = (1, 1)
            return sizes[key]
        active.add(key)
        children: list[yaml.Node] = []
        if isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        elif isinstance(node, yaml.MappingNode):
            children = [part for pair in node.value for part in pair]
        count, depth = 1, 0
        for child in children:
            child_count, child_depth = visit(child)
            count += child_count
            depth = max(depth, child_depth)
            if count > MAX_YAML_NODES:
                raise refused(f"more than {MAX_YAML_NODES} values once aliases are expanded", node)
        active.discard(key)
        if depth + 1 > MAX_YAML_DEPTH:
            deeper = f"nested deeper than {MAX_YAML_DEPTH} levels once aliases are expanded"
            raise refused(deeper, node)
        sizes[key] = (count, depth + 1)
        return sizes[key]

    visit(root)


def load_yaml(text: str) -> Any:
    """One YAML document, safely and within bounds; yaml.YAMLError for anything refused."""
    loader = _ScenarioLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_expanded(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def yaml_problem(err: yaml.YAMLError) -> str:
    """A PyYAML error as `YAML error at line N: problem`."""
    mark = getattr(err, "problem_mark", None)
    problem = getattr(err, "problem", None)
    if isinstance(err, yaml.reader.ReaderError):
        char = chr(err.character) if isinstance(err.character, int) else str(err.character)
        return f"YAML error: unacceptable character U+{ord(char[:1] or ' '):04X} in the file"
    where = f" at line {mark.line + 1}" if mark is not None else ""
    text = str(problem or "invalid YAML")
    context = getattr(err, "context", None)
    if context and text.startswith("but "):  # "expected a single document ..., but found ..."
        text = f"{context}, {text}"
    return f"YAML error{where}: {' '.join(text.split())}"
