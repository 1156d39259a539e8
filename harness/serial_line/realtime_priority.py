"""Ask Linux to run the calling thread under SCHED_FIFO, where it is allowed.

Real-time serial emulation paces each revolution to within a fraction of a
millisecond, but an ordinary thread on a busy two-core machine can wait
several milliseconds for a core: with two CPU hogs beside it, revolution
starts came up to 10 ms late. A SCHED_FIFO thread runs as soon as it is
woken. The priority is low among real-time ones (above every ordinary
thread, below the kernel's real-time threads such as migration and the
watchdog), and the threads that ask for it spend their time blocked in
select, so they cannot starve the machine (Linux also caps real-time
threads at 95 % of a core by default).

Standard library only: the bench's line reader imports it at start.
"""

from __future__ import annotations

import os

FIFO_PRIORITY = 10


def raise_to_realtime() -> bool:
    """SCHED_FIFO for the calling thread; False where not permitted (root or CAP_SYS_NICE
    is needed) or not Linux. Either way the caller goes on: only its timing differs."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(FIFO_PRIORITY))
    except (AttributeError, OSError):
        return False
    return True
