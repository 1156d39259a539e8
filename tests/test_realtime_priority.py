"""serial_line.realtime_priority: SCHED_FIFO for the calling thread only, or a plain False."""

from __future__ import annotations

import os
import threading

import pytest

from harness.serial_line import realtime_priority


def test_only_the_calling_thread_is_raised() -> None:
    seen: dict[str, object] = {}

    def body() -> None:
        seen["granted"] = realtime_priority.raise_to_realtime()
        seen["policy"] = os.sched_getscheduler(0)

    thread = threading.Thread(target=body)
    thread.start()
    thread.join(5.0)
    assert isinstance(seen["granted"], bool)
    assert (seen["policy"] == os.SCHED_FIFO) is seen["granted"]
    assert os.sched_getscheduler(0) == os.SCHED_OTHER  # this thread is untouched


def test_refused_is_false_not_an_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """An ordinary user is refused with EPERM. The tests run as root here, and the
    interpreter lives where an unprivileged user cannot run it, so the refusal is
    stood in for; the granted path above is the real one."""

    def refuse(*args: object) -> None:
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "sched_setscheduler", refuse)
    assert realtime_priority.raise_to_realtime() is False
