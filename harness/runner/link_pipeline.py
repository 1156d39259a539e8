"""A suite's links: the next scenarios' started ahead, finished ones left stopping behind.

Starting and stopping a node take longer than most scenarios, so a link
isolated from its neighbours (its own ROS domain and node) starts a few
scenarios ahead and stops while the next runs; every scenario still gets a
fresh node, and the suite waits for every link to close.

Why four ahead: for up to 0.6 s after a node starts its graph may not match
the harness's yet (``Ros2Link.open`` waits); short scenarios reach a link
started three ahead inside that window, four is mostly old enough (five was
no faster). Each waiting node holds a ROS domain: AHEAD + BEHIND + 1 of the
101, so about 14 suites fit on one machine; one that finds none free waits.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from typing import Generic, TypeVar

from harness.errors import ConfigError
from harness.links.base import Link

AHEAD = 4  # links started beyond the one running (see the module's docstring)
BEHIND = 2  # finished links left stopping before the suite waits for the oldest

Closed = Callable[[float], None]  # told the seconds the suite waited for the close
R = TypeVar("R")


class _Unmade:
    """A link that could not be made (a usage error), kept to be raised at its turn."""

    def __init__(self, error: ConfigError) -> None:
        self.error = error


class LinkPipeline:
    """Hands out the links of scenarios 0..count-1 in order, started ahead where allowed."""

    def __init__(
        self,
        make: Callable[[int], Link],
        count: int,
        *,
        overlap: bool,
        ahead: int = AHEAD,
        behind: int = BEHIND,
    ) -> None:
        self._make = make
        self._count = count
        self._ahead = ahead if overlap else 0
        self._behind = behind if overlap else 0
        self._started: deque[Link | _Unmade] = deque()  # made and started, not yet taken, in order
        self._next = 0  # the index of the next link to make
        self._stopping: deque[tuple[Link, Closed]] = deque()
        self._running: Link | None = None  # taken, not yet retired

    def take(self, index: int) -> Link:
        """The link of scenario `index` (the next in order), started; those after it
        start too, up to AHEAD. Opening it (waiting until ready) is the caller's."""
        if index != self._next - len(self._started):
            raise ValueError(f"links are taken in order: asked for {index}")
        self._start_until(index)
        link = self._started.popleft()
        if isinstance(link, _Unmade):
            raise link.error
        self._running = link
        self._start_until(index + self._ahead)
        return link

    def _start_until(self, last: int) -> None:
        while self._next <= min(last, self._count - 1):
            try:
                link: Link | _Unmade = self._make(self._next)
            except ConfigError as err:  # raised when its scenario is taken, not before
                link = _Unmade(err)
            self._next += 1
            self._started.append(link)
            if not isinstance(link, _Unmade):
                link.start()

    def retire(self, link: Link, closed: Closed) -> None:
        """Its scenario is over: stop it now; `closed` runs once closed, in scenario order."""
        if link is self._running:
            self._running = None
        link.stop()
        self._stopping.append((link, closed))
        while len(self._stopping) > self._behind:
            self._close_oldest()

    def _close_oldest(self) -> None:
        link, closed = self._stopping.popleft()
        started = time.perf_counter()
        link.close()
        closed(time.perf_counter() - started)

    def drain(self) -> None:
        """Close every link: stop the ones started ahead and never taken (no more will
        be started) and one whose run raised, then wait for all; finished links
        report in order. Safe to call again."""
        self._next = self._count
        running, self._running = self._running, None
        ahead = [link for link in self._started if not isinstance(link, _Unmade)]
        unused = [*([running] if running is not None else []), *ahead]
        self._started.clear()
        for link in unused:
            link.stop()
        try:
            while self._stopping:
                self._close_oldest()
        finally:
            for link in unused:
                link.close()


class ReportsBehind(Generic[R]):
    """Hands each finished result to `report` in order: at once, or with `behind` at `finish`.

    A serial link's next scenario follows its device's stream in real time:
    writing a report (seconds on a loaded machine) in between keeps the device
    streaming revolutions nobody judges, and beside it takes the interpreter
    from the pacing thread. So those reports wait for the device session;
    `finish` reports all still held, even on an error.
    """

    def __init__(self, report: Callable[[R], None], *, behind: bool) -> None:
        self._report = report
        self._behind = behind
        self._held: deque[R] = deque()

    def __call__(self, result: R) -> None:
        if self._behind:
            self._held.append(result)
        else:
            self._report(result)

    def finish(self) -> None:
        """Report every result held, in order. Safe to call again."""
        while self._held:
            self._report(self._held.popleft())
