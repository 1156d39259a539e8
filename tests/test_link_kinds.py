"""Link kinds declared once (harness/links/kinds.py): the classes agree, nobody else lists them.

Like tests/test_layout.py for imports, the source is read, not run: a link
name written as a string outside harness/links/ is counted (at most
``MAX_LITERALS``), and a list of two or more link names there is a list
that should have come from the table.
"""

from __future__ import annotations

import ast
import functools
import subprocess
import sys
from pathlib import Path

import pytest

from harness.links.base import link_class
from harness.links.kinds import KINDS, device_names, either, link_kind

ROOT = Path(__file__).resolve().parents[1]
HARNESS = ROOT / "harness"
LINKS = HARNESS / "links"
NOT_CODE = {"reference", "board_driver", "robot_models", "scenarios"}
# Names of the shipped links and devices, and the LD models' own names.
SHIPPED = {"inprocess", "ros2", "rplidar", "ldlidar"}
NAMES = SHIPPED | {"ld06", "ld19"}
MAX_LITERALS = 10


def _sources() -> list[Path]:
    return [
        path
        for path in sorted(HARNESS.rglob("*.py"))
        if LINKS not in path.parents and not NOT_CODE & set(path.relative_to(HARNESS).parts)
    ]


@functools.cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(), filename=str(path))


def _literals(path: Path) -> list[tuple[int, str]]:
    tree = _tree(path)
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and node.value in NAMES
    ]


def _lists_of_links(path: Path) -> list[int]:
    tree = _tree(path)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            named = [e for e in node.elts if isinstance(e, ast.Constant) and e.value in SHIPPED]
            if len(named) >= 2:
                found.append(node.lineno)
    return found


def test_link_names_are_rarely_spelled_outside_links() -> None:
    """At most ten link or device names as string literals in harness/ outside links/."""
    found = [
        f"{path.relative_to(ROOT)}:{line} {value!r}"
        for path in _sources()
        for line, value in _literals(path)
    ]
    assert len(found) <= MAX_LITERALS, "\n".join(found)


def test_no_list_of_links_outside_the_table() -> None:
    """Every list of links comes from harness.links.kinds."""
    found = [f"{p.relative_to(ROOT)}:{line}" for p in _sources() for line in _lists_of_links(p)]
    assert not found, found


@pytest.mark.ros
@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_each_class_is_what_its_row_says(name: str) -> None:
    """The class registered under a name lives in the row's module and agrees with it."""
    kind = link_kind(name)
    cls = link_class(name)
    assert cls.__module__ == kind.module and cls.name == name
    assert cls.serial_line == kind.serial_line
    profile = getattr(cls, "profile", None)
    assert (profile.name if profile is not None else None) == kind.device
    assert (LINKS / f"{kind.module.rsplit('.', 1)[1]}.py").is_file()


def test_the_table_is_the_shipped_links() -> None:
    """One default, the serial links name their devices, and every device has a profile."""
    from harness.devices.profiles import PROFILES

    assert set(KINDS) >= SHIPPED
    assert sum(kind.default for kind in KINDS.values()) == 1
    assert set(device_names()) <= set(PROFILES)
    assert either(["a", "b", "c"]) == "a, b or c" and either(["a"]) == "a"


def test_naming_the_links_imports_nothing_heavy() -> None:
    """The CLI and the plugin read the table at start: it imports no link, rclpy or numpy."""
    code = (
        "import sys, harness.links.kinds as k; k.link_names(); "
        "print(' '.join(sorted(m for m in sys.modules if m.startswith(('harness', 'rclpy', "
        "'numpy', 'serial')))))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    loaded = done.stdout.split()
    light = ["harness.errors", "harness.links", "harness.links.kinds", "harness.option_names"]
    assert loaded == ["harness", *light]
