"""Processing functions that misbehave, for the inprocess link's isolation tests.

Each is ``fn(scan, threshold) -> (status, warning)`` gone wrong in one way a
student's (or a hostile) function can go wrong.
"""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
import time
from pathlib import Path

from harness.links.inprocess import reference_processor


def exits_0(scan, threshold):
    sys.exit(0)


def raises_system_exit(scan, threshold):
    raise SystemExit("done")


def raises_keyboard_interrupt(scan, threshold):
    raise KeyboardInterrupt


def raises_generator_exit(scan, threshold):
    raise GeneratorExit


def hard_exit_0(scan, threshold):
    os._exit(0)


def segfaults(scan, threshold):
    ctypes.string_at(0)


def spins_forever(scan, threshold):
    while True:
        pass


def sleeps_forever(scan, threshold):
    time.sleep(3600)


def hangs_the_first_time(scan, threshold):
    """Hangs in the first scenario of a run, answers right ever after.

    The marker file is named in FOSSBOT_TEST_MARKER: the first child to
    call creates it and hangs; later children (later scenarios) see it.
    """
    marker = Path(os.environ["FOSSBOT_TEST_MARKER"])
    if not marker.exists():
        marker.touch()
        time.sleep(3600)
    return reference_processor(scan, threshold)


def hides_the_obstacle(scan, threshold):
    """Writes over the scan it was given, then claims the (rewritten) truth."""
    scan.ranges[:] = float("inf")
    return "no obstacle", False


def starts_a_process_and_hangs(scan, threshold):
    subprocess.Popen(["sleep", "3600"])
    time.sleep(3600)


def prints_escapes(scan, threshold):
    print("\x1b[2J\x1b[31mred\x1b[0m\x07 beam count", scan.ranges.size, flush=True)
    return reference_processor(scan, threshold)


def returns_nonsense(scan, threshold):
    return 42


class _Unprintable(Exception):
    def __str__(self) -> str:
        raise RuntimeError("no message for you")


def raises_unprintable(scan, threshold):
    raise _Unprintable


def slow_reference(scan, threshold):
    """The right answers, 20 ms late: a run long enough to interrupt.

    Each call adds a line to the file named in FOSSBOT_TEST_MARKER, so a
    test can tell how far the run got.
    """
    time.sleep(0.02)
    with open(os.environ["FOSSBOT_TEST_MARKER"], "a") as calls:
        calls.write("call\n")
    return reference_processor(scan, threshold)
