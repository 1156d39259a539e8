"""Reading a YAML launch file (``launch:``) from PyYAML's composed nodes, which know lines.

It becomes the same `Element`s as XML; only composed (never constructed), with the
safe loader, and an alias used twice is walked once, so no file makes the walk blow up."""

from __future__ import annotations

from pathlib import Path

import yaml

from harness.launch_files.entries import LaunchFile, Unread
from harness.launch_files.frontend import Element, launch_file

__all__ = ["read_yaml"]

MAX_NODES = 100_000  # composed nodes walked, at most


def read_yaml(text: str, path: Path, shown: str) -> LaunchFile | None:
    """The launch file's nodes and arguments; None when it has no top-level `launch:`."""
    try:
        document = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 1
        problem = " ".join(str(getattr(err, "problem", None) or err).split())
        return LaunchFile(path, shown, unread=(Unread(line, f"does not parse as YAML: {problem}"),))
    if not isinstance(document, yaml.MappingNode):
        return None
    launch = next(
        (v for k, v in document.value if isinstance(k, yaml.ScalarNode) and k.value == "launch"),
        None,
    )
    if launch is None:
        return None
    root = Element("launch", launch.start_mark.line + 1)
    _Builder().children(root, "launch", launch)
    return launch_file(root, path, shown)


class _Builder:
    """Composed YAML nodes -> Elements, each node visited once."""

    def __init__(self) -> None:
        self.seen: set[int] = set()

    def _fresh(self, node: yaml.Node) -> bool:
        if id(node) in self.seen or len(self.seen) >= MAX_NODES:
            return False
        self.seen.add(id(node))
        return True

    def element(self, tag: str, mapping: yaml.MappingNode) -> Element:
        """`tag: {key: scalar, key: [...]}`: scalars are attributes, the rest children."""
        element = Element(tag, mapping.start_mark.line + 1)
        for key, value in mapping.value:
            if not isinstance(key, yaml.ScalarNode) or not self._fresh(value):
                continue
            if isinstance(value, yaml.ScalarNode):
                element.attrs[key.value] = (value.value, value.start_mark.line + 1)
            else:
                self.children(element, key.value, value)
        return element

    def children(self, parent: Element, key: str, value: yaml.Node) -> None:
        """`key: [...]` items: `- node: {...}` wraps a child of its own tag; a bare
        mapping (`- name: x`) is a child tagged `key` (`param`)."""
        if isinstance(value, yaml.MappingNode):
            parent.children.append(self.element(key, value))
            return
        if not isinstance(value, yaml.SequenceNode):
            return
        for item in value.value:
            if not isinstance(item, yaml.MappingNode) or not self._fresh(item):
                continue
            wrapped = len(item.value) == 1 and isinstance(item.value[0][1], yaml.MappingNode)
            if wrapped and isinstance(item.value[0][0], yaml.ScalarNode):
                tag, inner = item.value[0][0].value, item.value[0][1]
                if self._fresh(inner):
                    parent.children.append(self.element(tag, inner))
            else:
                parent.children.append(self.element(key, item))
