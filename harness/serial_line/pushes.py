"""What the harness thread hands the server thread: pushed revolutions and idle requests.

Both sides hold one lock here (it also guards the pacer and the revolutions
sent). In realtime a push still waiting for its slot is replaced by a newer
one: a real sensor reports the present.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from harness.serial_line.stats import ServerCounts
from harness.serial_line.stream_policy import Push

__all__ = ["Pushes", "Taken"]


@dataclass(frozen=True)
class Taken:
    """What the server thread takes in one tick (``StreamPolicy.advance``'s arguments)."""

    push: Push | None
    whole_marker: bool
    idle_request: tuple[Sequence[Any], float] | None
    idling: bool


class Pushes:
    """The mailbox between the two threads; every method takes `lock` itself."""

    def __init__(self, lock: threading.Lock, counts: ServerCounts, *, realtime: bool) -> None:
        self.lock, self.counts, self.realtime = lock, counts, realtime
        self._inbox: deque[Push] = deque()
        self._count = 0  # ids of pushed revolutions
        # Continuous lockstep: between scenarios the last revolution streams every period.
        self._idling = False
        self._idle_request: tuple[Sequence[Any], float] | None = None  # held samples, period
        self._whole_marker = False  # end the stream on a whole start marker, first
        self.quiet = threading.Event()  # the thread saw the idle stream end
        self.idle = threading.Event()  # nothing pushed waits and nothing is left to write
        self.idle.set()

    @property
    def waiting(self) -> bool:
        """A pushed revolution waits for the thread (read without the lock: a hint)."""
        return bool(self._inbox)

    @property
    def idling(self) -> bool:
        return self._idling

    def push(self, samples: Sequence[Any], tick: int, period_s: float) -> int:
        """Queue one revolution (ending the idle stream); returns its id."""
        with self.lock:
            if self.realtime and self._inbox:
                self._inbox.popleft()
                self.counts.revolutions_superseded += 1
            self._count += 1
            self._inbox.append((list(samples), tick, period_s, self._count))
            self._idling = False
            self.idle.clear()
            return self._count

    def stream_idle(self, samples: Sequence[Any] | None, period_s: float) -> None:
        """Stream `samples` (else the last revolution) until the next push; lockstep repeats
        it every period, realtime once nothing new comes anyway."""
        with self.lock:
            if samples is not None:
                self._idle_request = (list(samples), period_s)
            self._idling = not self.realtime

    def end_idle(self) -> bool:
        """Stop the lockstep idle stream, on a whole marker; False if it was not streaming."""
        with self.lock:
            was, self._idling = self._idling, False
            if not (was and not self.realtime):
                return False
            self._whole_marker = True
            self.quiet.clear()
            return True

    def align(self) -> None:
        """Lockstep: a whole start marker before the next push."""
        with self.lock:
            self._whole_marker = not self.realtime

    def settle(self, pending: bool) -> None:
        """The server thread's tick is over: idle if no push waits and nothing is `pending`."""
        with self.lock:
            if not (self._inbox or pending):
                self.idle.set()

    def take(self, slot_open: Callable[[], bool]) -> Taken:
        """The server thread's share for this tick; a push only if its slot is open."""
        with self.lock:  # a whole marker asked for goes before anything pushed after it
            whole, self._whole_marker = self._whole_marker, False
            push = self._inbox.popleft() if self._inbox and slot_open() else None
            request, self._idle_request = self._idle_request, None
            return Taken(push, whole, request, self._idling)
