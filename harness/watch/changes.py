"""File changes, seen by watchfiles in background threads and queued for the loop.

The threads watch on while the loop runs scenarios or a build, so nothing
saved meanwhile is lost, and watchfiles' debouncing runs nothing twice for
one save. Signals stay the main thread's: its bounded waits see Ctrl-C.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from harness.errors import HarnessError, one_line
from harness.option_names import named
from harness.watch.sources import Watched

__all__ = ["ChangeFeed", "Changes"]

DEBOUNCE_MS = 1600  # at most this long gathering one burst of events (watchfiles' default)
STEP_MS = 50  # a burst ends after this long without a new event
TICK_MS = 100  # each watcher looks at its stop flag at least this often
READY_WAIT_S = 10.0  # for the watchers to start (inotify set-up of a big package)
STOP_WAIT_S = 2.0


@dataclass(frozen=True)
class Changes:
    """Files that changed, and when the first batch of them was seen (time.monotonic)."""

    paths: frozenset[Path] = field(default_factory=frozenset)
    seen_at: float = 0.0

    def __or__(self, other: Changes) -> Changes:
        first = min(t for t in (self.seen_at, other.seen_at) if t) if self or other else 0.0
        return Changes(self.paths | other.paths, first)

    def __bool__(self) -> bool:
        return bool(self.paths)


class ChangeFeed:
    """Watch `watched` (with `matches` deciding which changed files count) from the
    `with` on; `wait` returns what changed since it was last asked."""

    def __init__(self, watched: Sequence[Watched], matches: Callable[[Path], bool]) -> None:
        self._groups: dict[bool, list[Path]] = {}
        for w in watched:
            folders = self._groups.setdefault(w.recursive, [])
            if w.folder not in folders:
                folders.append(w.folder)
        self._matches = matches
        self._queue: queue.Queue[Changes | str] = queue.Queue()
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._ready: list[threading.Event] = []
        self._failures: list[str] = []  # why a watcher stopped (appended by its thread)

    def __enter__(self) -> ChangeFeed:
        for recursive, folders in self._groups.items():
            ready = threading.Event()
            thread = threading.Thread(
                target=self._watch,
                args=(folders, recursive, ready),
                name="fossbot-hil-watch",
                daemon=True,  # never keeps the process alive; stopped by __exit__ first
            )
            thread.start()
            self._threads.append(thread)
            self._ready.append(ready)
        deadline = time.monotonic() + READY_WAIT_S
        for ready in self._ready:
            ready.wait(max(0.0, deadline - time.monotonic()))
        self._raise_failure()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        deadline = time.monotonic() + STOP_WAIT_S
        for thread in self._threads:
            thread.join(max(0.0, deadline - time.monotonic()))

    def _watch(self, folders: list[Path], recursive: bool, ready: threading.Event) -> None:
        """A watcher thread: each batch of changes that count goes into the queue."""
        import watchfiles

        def counts(change: watchfiles.Change, path: str) -> bool:
            return self._matches(Path(path))

        try:
            for batch in watchfiles.watch(
                *folders,
                watch_filter=counts,
                debounce=DEBOUNCE_MS,
                step=STEP_MS,
                stop_event=self._stop,
                rust_timeout=TICK_MS,
                yield_on_timeout=True,  # an empty batch: the watcher is up
                raise_interrupt=False,
                recursive=recursive,
            ):
                ready.set()
                if batch:
                    paths = frozenset(Path(path) for _, path in batch)
                    self._queue.put(Changes(paths, time.monotonic()))
        except Exception as err:  # a folder gone, the inotify limit reached: the loop says so
            problem = f"cannot watch {', '.join(map(str, folders))}: {one_line(err)}"
            self._failures.append(problem)
            self._queue.put(problem)
        finally:
            ready.set()

    def _raise_failure(self) -> None:
        """A watcher that failed to start ends the loop (the reason, in one line)."""
        if self._failures:
            self._stop.set()
            raise HarnessError(f"{named('watch')}: {self._failures[0]}")

    def wait(self, timeout: float) -> Changes:
        """Everything that changed since the last call, waiting up to `timeout` seconds for
        the first change (an empty Changes when none came)."""
        found = Changes()
        deadline = time.monotonic() + timeout
        while True:
            try:
                remaining = deadline - time.monotonic()
                item = self._queue.get(timeout=remaining) if remaining > 0 and not found else None
                if item is None:
                    item = self._queue.get_nowait()
            except queue.Empty:
                return found
            if isinstance(item, str):
                raise HarnessError(f"{named('watch')}: {item}")
            found = found | item
