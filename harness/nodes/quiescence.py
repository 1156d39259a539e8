"""Has a process done all the work it was given? Every thread asleep, several looks running.

A node with scans queued keeps a thread runnable; one that answered all sleeps. /proc
tells each thread's state, and "all asleep, a few looks a few ms apart" holds on a
loaded machine too, where a process behind is runnable, not asleep."""

from __future__ import annotations

import time
from collections.abc import Iterable
from pathlib import Path

__all__ = ["Quiescence", "asleep"]

ASLEEP = frozenset("SI")  # sleeping, idle kernel thread; T/t (stopped) are not done either


def asleep(pid: int) -> bool | None:
    """Every thread of `pid` asleep; None when the process is gone (or not ours to read)."""
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
        for task in tasks:
            state = (task / "stat").read_bytes().rsplit(b")", 1)[1].split()[0].decode()
            if state not in ASLEEP:
                return False
    except (OSError, IndexError):
        return None
    return True


class Quiescence:
    """Call it until it says True: every process asleep in `looks` looks, `gap_s` apart."""

    def __init__(self, pids: Iterable[int], *, looks: int = 3, gap_s: float = 0.01) -> None:
        self.pids = list(pids)
        self.looks, self.gap_s = looks, gap_s
        self._streak = 0
        self._last = 0.0

    def __call__(self) -> bool:
        now = time.perf_counter()
        if now - self._last < self.gap_s:
            return False
        self._last = now
        states = [asleep(pid) for pid in self.pids]
        self._streak = self._streak + 1 if all(s is not False for s in states) else 0
        return self._streak >= self.looks
