"""How this process's caller names each run option, so lower layers never spell a flag.

A message below commands/ names an option by its key in braces ("{launch}
starts the node itself: drop {node}"); the caller that owns the process (the
CLI, the pytest plugin, a grading worker) says once, with `speak`, how its
user writes each key ("--launch", "--hil-launch", the grading file's
"launch"), and `worded` fills them in. A key nobody named is shown as the key.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager

#: How a caller names each option key in a message ("--seed", "--hil-seed", "seed=").
Names = Mapping[str, str]


class _AsKey(dict[str, str]):
    """A key the caller has no name for is shown as the key itself."""

    def __missing__(self, key: str) -> str:
        return key


_spoken: dict[str, str] = {}


def speak(names: Names) -> None:
    """Name the options as this process's caller does (called once, at its entry)."""
    _spoken.clear()
    _spoken.update(names)


@contextmanager
def speaking(names: Names) -> Iterator[None]:
    """`speak` for the length of a call (the CLI's `main`, a plugin's run), then as before."""
    before = dict(_spoken)
    speak(names)
    try:
        yield
    finally:
        speak(before)


def spoken() -> dict[str, str]:
    """The names this process speaks now (to hand on to its workers)."""
    return dict(_spoken)


def named(key: str) -> str:
    """The caller's name for option `key` ("--port" in the CLI, "--hil-port" in pytest)."""
    return _spoken.get(key, key)


def escaped(text: str) -> str:
    """Text from elsewhere (a value, another library's error), safe in a template."""
    return text.replace("{", "{{").replace("}", "}}")


def worded(template: str, names: Names | None = None) -> str:
    """`template` with each ``{key}`` as `names` (by default the caller's) name it."""
    return template.format_map(_AsKey(_spoken if names is None else names))
