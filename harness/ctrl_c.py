"""Ctrl-C that cannot be lost: an event that every SIGINT sets.

Python swallows a KeyboardInterrupt raised inside a weakref callback or a
``__del__`` ("Exception ignored in ..."). A loop that must end on Ctrl-C
(watch, sim) checks the event at each turn and raises KeyboardInterrupt
itself when the signal's own one was lost on the way.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType


@contextlib.contextmanager
def remembered_ctrl_c() -> Iterator[threading.Event]:
    """An event set by every Ctrl-C while the block runs (in the main thread; elsewhere
    signals are not ours to handle, and the event is never set)."""
    pressed = threading.Event()
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous == signal.SIG_IGN:
        yield pressed
        return

    def on_ctrl_c(signum: int, frame: FrameType | None) -> None:
        pressed.set()
        if callable(previous):
            previous(signum, frame)
        else:
            signal.default_int_handler(signum, frame)

    signal.signal(signal.SIGINT, on_ctrl_c)
    try:
        yield pressed
    finally:
        signal.signal(signal.SIGINT, previous)
