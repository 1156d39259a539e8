"""The order of a re-run: what failed last time first, as `pytest --ff` does (pure)."""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from operator import attrgetter
from typing import TypeVar

__all__ = ["failed_first"]

T = TypeVar("T")


def failed_first(
    items: Sequence[T], failed: Collection[str], name: Callable[[T], str] = attrgetter("name")
) -> list[T]:
    """`items` whose name is in `failed` first, then the others; each part keeps its
    given order (a failure is seen soonest, and the order stays predictable)."""
    first = [item for item in items if name(item) in failed]
    return first + [item for item in items if name(item) not in failed]
