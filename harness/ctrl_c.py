"""Ctrl-C that cannot be lost: an event that every SIGINT sets, and stops held
over a few lines that must not be cut in two.

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


STOPS = (signal.SIGINT, signal.SIGTERM)  # the signals the CLI turns into KeyboardInterrupt


@contextlib.contextmanager
def stops_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM wait until the block is over, then act as they would have.

    For state that a KeyboardInterrupt must never see half made, such as fds 1 and 2
    pointed at a capture: a stop landing there leaves them so, and the summary written
    after the stop goes into a deleted file. Only the main thread runs Python's signal
    handlers, so elsewhere nothing needs holding.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous = {signum: signal.getsignal(signum) for signum in STOPS}

    def hold(signum: int, frame: FrameType | None) -> None:
        held.append(signum)

    for signum, handler in previous.items():
        if handler is not None and handler != signal.SIG_IGN:
            signal.signal(signum, hold)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            if handler is not None and handler != signal.SIG_IGN:
                signal.signal(signum, handler)
        if held:  # through the handler in place again: the same stop, just later
            signal.raise_signal(held[0])
