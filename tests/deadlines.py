"""Per-scan deadlines for tests that run a real node, with margins from this machine.

A deadline costs time only where it is waited out: where no answer comes. A
test whose node must answer every scan in time gets a generous deadline
(GENEROUS_S), which a right answer never waits out. A test whose node answers
some scans and then none (it hangs, falls silent, stops publishing) waits out
each unanswered scan's deadline and the harness's catch-up wait after it, and a
run in real time waits out every scan's period, which is its deadline too:
those deadlines are short, but never shorter than this machine needs now to
carry the answers that must come in time (short_deadline): a floor that covers
Fast DDS's own repair delays, or a multiple of the slowest round trip between
two processes measured here and now, whichever is longer.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

from harness.links.ros2 import CATCH_UP_S

# A right answer must come within this: a loaded CI machine has held a node's answer back
# 3 s (seen on a board in real time); a right node never waits it out.
GENEROUS_S = 5.0
# A node's start and its first answer (--ready-timeout), where neither is waited out (the
# node comes up, or is told at once what it does wrong): a loaded machine has taken more
# than 5 s for a flooding node's first answer.
GENEROUS_READY_S = 30.0

# The shortest deadline a run waits out (its node must still answer the scans before in
# time): twice what a quiet machine's 0.3 s was, above the 0.1-0.45 s Fast DDS has taken to
# repair a young node's sample (timer-bound, whatever the load), and no dearer to wait out
# than 0.3 s was but for itself: the catch-up wait after a missed deadline is
# max(CATCH_UP_S, 3 deadlines), CATCH_UP_S up to CATCH_UP_S / 3.
FLOOR_S = 0.6
assert FLOOR_S <= CATCH_UP_S / 3
# An answer is a scan's way to the node and back, a round trip between two processes,
# with DDS's threads woken on each side: on this 2-core machine, loaded (two busy loops,
# three test workers), a run's slowest answer took up to ten times the slowest round trip
# measured beside it; twenty leave twice that.
ROUND_TRIPS = 20
# Beyond this the tests' own bounds (a run's time limit, pytest's timeout) would need to
# grow too: three missed deadlines and their catch-up waits take 3 * (2 + 6) = 24 s.
CEILING_S = 2.0

PROBE_S = 0.3  # how long the round trips are measured
_ECHO = "import os\nwhile os.write(1, os.read(0, 1)):\n    pass\n"


def slowest_round_trip(seconds: float = PROBE_S) -> float:
    """The longest a byte took to go to another process and back, over `seconds` of
    round trips (one every 2 ms): how long this machine, now, keeps a woken process
    waiting for a core, twice."""
    echo = subprocess.Popen(
        [sys.executable, "-S", "-c", _ECHO], stdin=subprocess.PIPE, stdout=subprocess.PIPE
    )
    assert echo.stdin is not None and echo.stdout is not None
    to, back = echo.stdin.fileno(), echo.stdout.fileno()
    try:
        os.write(to, b"x")
        os.read(back, 1)  # the echo runs: its start-up is not a round trip
        slowest = 0.0
        end = time.perf_counter() + seconds
        while time.perf_counter() < end:
            sent = time.perf_counter()
            os.write(to, b"x")
            os.read(back, 1)
            slowest = max(slowest, time.perf_counter() - sent)
            time.sleep(0.002)
    finally:
        echo.stdin.close()
        echo.wait(timeout=10)
        echo.stdout.close()
    return slowest


def short_deadline() -> float:
    """A per-scan deadline (seconds, to 0.01) for a run that waits it out (a node that
    answers some scans in time and then none; a scan period in real time): FLOOR_S, or
    ROUND_TRIPS times the slowest round trip measured now, whichever is longer, at most
    CEILING_S."""
    measured = ROUND_TRIPS * slowest_round_trip()
    return round(min(CEILING_S, max(FLOOR_S, measured)), 2)
