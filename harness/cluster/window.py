"""Feeding tasks to a cluster no faster than its workers take them.

Dask hands a task to a worker as soon as it is submitted, unless the task
is one of a group much larger than the cluster ("root-ish"): a class of
students (a task group each) or a small campaign is handed out at once, two
or more tasks to a worker. A worker that dies makes every task it held
suspect, and Dask gives up on a task suspected ``allowed-failures`` + 1
times, so a node that kills its worker would take innocent tasks down with
it. Our tasks are long, so the command keeps at most as many of them on the
cluster as it has worker threads: each worker holds only the task it runs,
and a killed worker costs that task alone.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import Any, Generic, TypeVar

from harness.errors import HarnessError, one_line

Item = TypeVar("Item")


def cluster_threads(client: Any) -> int:
    """Worker threads the cluster has now (at least 1, so a cluster between workers waits)."""
    try:
        threads = client.nthreads()
    except Exception as err:  # noqa: BLE001 - the scheduler went away
        raise HarnessError(f"lost the Dask scheduler: {one_line(err)}") from None
    return max(1, sum(threads.values()))


class Window(Generic[Item]):
    """Submits `items` through `submit` as threads free up; iterate for (index, future) as
    each finishes. `running` holds the futures on the cluster now."""

    def __init__(self, client: Any, items: Sequence[Item], submit: Callable[[Item], Any]) -> None:
        from distributed import as_completed

        self.client = client
        self.items = items
        self.submit = submit
        self.running: dict[Any, int] = {}
        self._next = 0
        self._finished = as_completed()

    def _top_up(self) -> None:
        room = cluster_threads(self.client) - len(self.running)
        while room > 0 and self._next < len(self.items):
            future = self.submit(self.items[self._next])
            self.running[future] = self._next
            self._finished.add(future)
            self._next += 1
            room -= 1

    def __iter__(self) -> Iterator[tuple[int, Any]]:
        self._top_up()
        for future in self._finished:
            index = self.running.pop(future)
            self._top_up()  # before the caller's work on this one: keep the workers busy
            yield index, future
