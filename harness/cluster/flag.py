"""A stop flag the command sets and every task on every worker can read: a Dask Event.

A running Dask task cannot be interrupted from outside, so a long task (a
student's build and suite) looks at this flag while it waits on its child
processes and stops them itself. Reading it asks the scheduler, so a read
is answered from the last answer for ``RECHECK_S``; the flag travels to
workers by name only.
"""

from __future__ import annotations

import time
import uuid
from typing import Any

RECHECK_S = 0.25  # how stale a worker's view of the flag may be


class ClusterFlag:
    """``set()`` here, ``is_set()`` anywhere on the cluster (a threading.Event's interface)."""

    def __init__(self, name: str | None = None) -> None:
        self.name = name or f"fossbot-hil-stop-{uuid.uuid4().hex}"
        self._event: Any = None
        self._seen = False
        self._checked = -RECHECK_S

    def __getstate__(self) -> dict[str, str]:
        return {"name": self.name}  # a worker opens its own Event on the same name

    def __setstate__(self, state: dict[str, str]) -> None:
        self.__init__(state["name"])  # type: ignore[misc]

    def _opened(self) -> Any:
        if self._event is None:
            from distributed import Event

            self._event = Event(self.name)
        return self._event

    def set(self) -> None:
        self._seen = True
        self._opened().set()

    def is_set(self) -> bool:
        if self._seen:
            return True
        now = time.monotonic()
        if now - self._checked >= RECHECK_S:
            self._checked = now
            try:
                self._seen = bool(self._opened().is_set())
            except Exception:  # the scheduler is gone: so is the command that could set it
                return False
        return self._seen
