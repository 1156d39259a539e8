"""Reading an XML launch file (``<launch>``) with expat, which knows each element's line;
DTDs and entities are refused (a launch file needs none; they make expansion bombs)."""

from __future__ import annotations

from pathlib import Path
from xml.parsers import expat

from harness.launch_files.entries import LaunchFile, Unread
from harness.launch_files.frontend import Element, launch_file

__all__ = ["read_xml"]


class _Refused(Exception):
    """A construct no launch file needs (a DTD, an entity)."""


def read_xml(text: str, path: Path, shown: str) -> LaunchFile | None:
    """The launch file's nodes and arguments; None when its root is not <launch>."""
    parser = expat.ParserCreate()
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        line = parser.CurrentLineNumber
        element = Element(tag, line, {k: (v, line) for k, v in attrs.items()})
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    def refuse(*args: object) -> None:
        raise _Refused

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = refuse
    parser.EntityDeclHandler = refuse
    try:
        parser.Parse(text, True)
    except expat.ExpatError as err:
        problem = f"does not parse as XML: {expat.ErrorString(err.code)}"
        return LaunchFile(path, shown, unread=(Unread(err.lineno, problem),))
    except _Refused:
        problem = "has a document type declaration or entities, which a launch file needs not"
        return LaunchFile(path, shown, unread=(Unread(parser.CurrentLineNumber, problem),))
    if not roots or roots[0].tag != "launch":
        return None
    return launch_file(roots[0], path, shown)
