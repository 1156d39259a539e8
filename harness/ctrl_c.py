"""Ctrl-C that cannot be lost: an event that every SIGINT sets.

Python swallows a KeyboardInterrupt raised inside a weakref callback or a
``__del__`` ("Exception ignored in ..."). A loop that must end on Ctrl-C
(watch, sim) checks the event at each turn and raises KeyboardInterrupt
itself when the signal's own one was lost on the way; Python's "Exception
ignored" report of the lost one (a traceback on the user's screen) is not
printed.
"""

from __future__ import annotations

import contextlib
import signal
import sys
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

    previous_hook = sys.unraisablehook

    def on_unraisable(unraisable: sys.UnraisableHookArgs) -> None:
        kind = unraisable.exc_type
        lost = kind is not None and issubclass(kind, KeyboardInterrupt)
        if not (lost and pressed.is_set()):  # a lost Ctrl-C: the loop raises it again
            previous_hook(unraisable)

    signal.signal(signal.SIGINT, on_ctrl_c)
    sys.unraisablehook = on_unraisable
    try:
        yield pressed
    finally:
        signal.signal(signal.SIGINT, previous)
        sys.unraisablehook = previous_hook
