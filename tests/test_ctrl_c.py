"""Ctrl-C inside a weakref callback or a __del__ is lost by Python, not by the loops."""

from __future__ import annotations

import signal
import sys
from collections.abc import Iterator

import pytest

from harness.ctrl_c import remembered_ctrl_c


class _RaisesCtrlCWhenCollected:
    def __del__(self) -> None:
        signal.raise_signal(signal.SIGINT)  # its KeyboardInterrupt is raised in here


class _BrokenFinaliser:
    def __del__(self) -> None:
        raise ValueError("in a finaliser")


@pytest.fixture
def reported() -> Iterator[list[type[BaseException] | None]]:
    """What reaches the unraisable hook in place before the block (Python's prints the
    "Exception ignored in ..." traceback on stderr)."""
    seen: list[type[BaseException] | None] = []
    previous = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: seen.append(unraisable.exc_type)
    try:
        yield seen
    finally:
        sys.unraisablehook = previous


def test_a_ctrl_c_lost_in_a_finaliser_is_remembered_and_not_reported(
    reported: list[type[BaseException] | None],
) -> None:
    """Python swallows it and reports it as ignored, with a traceback on the user's
    screen (seen after a Ctrl-C during `run --watch`): the event keeps it for the loop,
    and it is not reported."""
    with remembered_ctrl_c() as pressed:
        doomed = _RaisesCtrlCWhenCollected()
        del doomed  # no KeyboardInterrupt comes out of here
        assert pressed.is_set()
    assert reported == []


def test_other_lost_exceptions_are_still_reported(
    reported: list[type[BaseException] | None],
) -> None:
    """Only a lost Ctrl-C is kept quiet: anything else goes to the hook before ours."""
    with remembered_ctrl_c():
        broken = _BrokenFinaliser()
        del broken
    assert reported == [ValueError]
