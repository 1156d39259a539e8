"""The XML and YAML launch formats share one shape (elements with attributes and
children): nodes, parameters and arguments are read out of it here, for both."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from harness.launch_files.entries import LaunchFile, NodeEntry, ParamSetting, Unread

__all__ = ["Element", "launch_file"]

SUBSTITUTION = "$("  # $(var x), $(find-pkg-share p): known only when the file runs


@dataclass
class Element:
    """One element: its tag, attributes (value and line of each), line and children."""

    tag: str
    line: int
    attrs: dict[str, tuple[str, int]] = field(default_factory=dict)
    children: list[Element] = field(default_factory=list)

    def text(self, name: str) -> str | None:
        given = self.attrs.get(name)
        return given[0] if given is not None else None

    def line_of(self, name: str) -> int:
        given = self.attrs.get(name)
        return given[1] if given is not None else self.line


def launch_file(root: Element, path: Path, shown: str) -> LaunchFile:
    """The file whose <launch> element is `root`."""
    nodes: list[NodeEntry] = []
    arguments: list[str] = []
    unread: list[Unread] = []
    for element in _elements(root):
        if element.tag == "arg":
            name = element.text("name")
            if name and SUBSTITUTION not in name:
                arguments.append(name)
        elif element.tag == "node":
            nodes.append(_node(element, unread))
    unread.sort(key=lambda u: u.line)
    return LaunchFile(path, shown, tuple(nodes), tuple(arguments), tuple(unread))


def _elements(root: Element) -> Iterator[Element]:
    """Every element below `root` (groups, includes' siblings), not inside a node."""
    stack = list(reversed(root.children))
    while stack:
        element = stack.pop()
        yield element
        if element.tag != "node":
            stack.extend(reversed(element.children))


def _node(element: Element, unread: list[Unread]) -> NodeEntry:
    package = _plain(element, "pkg", unread)
    if element.text("exec") is None and element.text("type") is not None:
        why = "type= is ROS 1's name: ROS 2's launch reads exec= (this node does not start)"
        unread.append(Unread(element.line_of("type"), why))
        executable = None
    else:
        executable = _plain(element, "exec", unread)
    name = element.text("name")
    params: list[ParamSetting] = []
    for child in element.children:
        if child.tag == "param":
            _param(child, "", params, unread)
    name = name if name and SUBSTITUTION not in name else None
    return NodeEntry(element.line, package, executable, name, tuple(params))


def _plain(element: Element, name: str, unread: list[Unread]) -> str | None:
    value = element.text(name)
    if value is None:
        unread.append(Unread(element.line, f"<node> gives no {name}="))
        return None
    if SUBSTITUTION in value:
        why = f"{name}={value!r} is known only when the file runs: that node is not checked"
        unread.append(Unread(element.line_of(name), why))
        return None
    return value


def _param(element: Element, prefix: str, params: list[ParamSetting], unread: list[Unread]) -> None:
    source = element.text("from")
    if source is not None:
        why = f"parameters from {source!r} (a parameter file) are not read: not checked"
        unread.append(Unread(element.line_of("from"), why))
        return
    name = element.text("name")
    if name is None:
        return
    if SUBSTITUTION in name:
        why = f"parameter name {name!r} is known only when the file runs: not checked"
        unread.append(Unread(element.line_of("name"), why))
        return
    inner = [child for child in element.children if child.tag == "param"]
    if inner:
        for child in inner:
            _param(child, f"{prefix}{name}.", params, unread)
    else:
        params.append(ParamSetting(prefix + name, element.line_of("name")))
