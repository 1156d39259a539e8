"""requirements/ci.txt, the lock CI installs with `--require-hashes --no-deps`.

`--no-deps` trusts the lock to be whole, so these check that it is: every
line pinned and hashed, everything pyproject.toml (with the `ros` extra)
and requirements/ci.in ask for pinned at a version they accept, and every
dependency of a pinned package pinned too (read from the installed
packages' metadata where the installed version is the pinned one).
"""

from __future__ import annotations

import re
from importlib import metadata

import pytest
from ci_template_steps import LOCK, ROOT
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11+")

_PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==(\S+) \\$")


def pins() -> dict[str, Version]:
    """The lock's pins by canonical name; asserts every one carries sha256 hashes."""
    found: dict[str, Version] = {}
    blocks = re.split(r"\n(?=[A-Za-z0-9])", LOCK.read_text())
    for block in blocks[1:]:  # the first is the header comment
        first = block.splitlines()[0]
        pin = _PIN.match(first)
        assert pin, f"not a hashed pin: {first!r}"
        assert re.search(r"--hash=sha256:[0-9a-f]{64}", block), f"{first}: no hash"
        found[canonicalize_name(pin.group(1))] = Version(pin.group(2))
    return found


def wanted() -> list[Requirement]:
    """What the lock must satisfy: the harness's dependencies, its `ros` extra, ci.in."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    lines = [*project["dependencies"], *project["optional-dependencies"]["ros"]]
    ci_in = (ROOT / "requirements" / "ci.in").read_text().splitlines()
    lines += [line for line in ci_in if line.strip() and not line.startswith("#")]
    return [Requirement(line) for line in lines]


def test_every_line_is_pinned_with_hashes() -> None:
    """A hash-checked install needs `name==version` and its hashes on every entry."""
    assert len(pins()) > 50


def test_lock_satisfies_the_harness_and_ci() -> None:
    """Every requirement is pinned at a version it accepts (regenerate: docs/ci.md)."""
    locked = pins()
    for requirement in wanted():
        name = canonicalize_name(requirement.name)
        assert name in locked, f"{requirement} is not in {LOCK.name}: run requirements/compile"
        assert requirement.specifier.contains(locked[name], prereleases=True), (
            f"{requirement} does not accept the pinned {locked[name]}: run requirements/compile"
        )


def test_lock_is_whole() -> None:
    """Each pinned package's own dependencies (with the extras asked for) are pinned."""
    locked = pins()
    todo = [(canonicalize_name(r.name), frozenset(r.extras)) for r in wanted()]
    seen: set[tuple[str, frozenset[str]]] = set()
    checked = 0
    while todo:
        name, extras = todo.pop()
        if (name, extras) in seen:
            continue
        seen.add((name, extras))
        try:
            dist = metadata.distribution(name)
        except metadata.PackageNotFoundError:
            continue
        if Version(dist.version) != locked[name]:
            continue  # another version installed here: its metadata says nothing of the pin's
        checked += 1
        for line in dist.requires or []:
            dependency = Requirement(line)
            environments = [{"extra": e} for e in extras] or [{"extra": ""}]
            marker = dependency.marker
            if marker is not None and not any(marker.evaluate(env) for env in environments):
                continue
            dep = canonicalize_name(dependency.name)
            assert dep in locked, f"{name} needs {dependency}, which {LOCK.name} does not pin"
            todo.append((dep, frozenset(dependency.extras)))
    assert checked > 50  # most of the lock is installed here at its pinned version
