"""Ask Linux to run the calling thread under SCHED_FIFO, where it is allowed.

With two CPU hogs beside it an ordinary thread started revolutions up to
10 ms late. The priority is the lowest real-time one and the threads that
ask for it sit in select, so they cannot starve the machine (Linux also
caps real-time threads at 95 % of a core). Standard library only: the
bench's line reader imports it at start.
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
