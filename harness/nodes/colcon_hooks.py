"""The environment sourcing a colcon workspace would give, read from its hook files (pure).

``install/setup.bash`` runs each package's ``share/PKG/package.dsv`` (lines such as
``prepend-non-duplicate;PYTHONPATH;lib/python3.11/site-packages``); reading them gives
the same environment without a shell, including a ``--symlink-install`` build's hook."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

PACKAGES = Path("share/colcon-core/packages")
MAX_SOURCED = 100  # hook files per prefix: a loop of `source` lines ends here


def colcon_packages(prefix: Path) -> list[str]:
    """The packages colcon installed into `prefix` (empty when it was not colcon)."""
    folder = prefix / PACKAGES
    if not folder.is_dir():
        return []
    return sorted(p.name for p in folder.iterdir() if p.is_file())


def hook_environment(prefixes: list[Path], base: Mapping[str, str]) -> dict[str, str]:
    """The variables the packages' hooks of `prefixes` set, changed from `base`; the
    first prefix ends up first on every path, as sourcing them in reverse would."""
    env = dict(base)
    for prefix in reversed(prefixes):
        for package in colcon_packages(prefix):
            _source(prefix, prefix / "share" / package / "package.dsv", env, [0])
    return {name: value for name, value in env.items() if base.get(name) != value}


def _source(prefix: Path, hook: Path, env: dict[str, str], count: list[int]) -> None:
    count[0] += 1
    if count[0] > MAX_SOURCED:
        return
    try:
        lines = hook.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return
    for line in lines:
        kind, _, rest = line.strip().partition(";")
        if kind == "source":
            target = (prefix / rest).resolve() if not os.path.isabs(rest) else Path(rest)
            if target.suffix == ".dsv":
                _source(prefix, target, env, count)
            continue
        name, _, values = rest.partition(";")
        if not name:
            continue
        paths = [_absolute(prefix, v) for v in values.split(";")]
        if kind in ("prepend-non-duplicate", "prepend-non-duplicate-if-exists"):
            if kind.endswith("if-exists"):
                paths = [p for p in paths if os.path.exists(p)]
            _add(env, name, paths, first=True)
        elif kind == "append-non-duplicate":
            _add(env, name, paths, first=False)
        elif kind == "set":
            env[name] = values
        elif kind == "set-if-unset" and name not in env:
            env[name] = values


def _absolute(prefix: Path, value: str) -> str:
    """A hook's value: relative to the prefix (empty: the prefix itself)."""
    return value if os.path.isabs(value) else str(prefix / value) if value else str(prefix)


def _add(env: dict[str, str], name: str, paths: list[str], *, first: bool) -> None:
    old = [p for p in env.get(name, "").split(os.pathsep) if p]
    new = [p for p in paths if p not in old] if not first else paths
    kept = [p for p in old if p not in paths] if first else old
    joined = [*new, *kept] if first else [*kept, *new]
    if joined:
        env[name] = os.pathsep.join(joined)
