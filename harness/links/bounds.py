"""The node exchange's bounded waits, in one table the links and the board session read.

Each wait counts from when the harness starts waiting for that thing
(docs/contract.md). The board's driver is started with a no-data timeout
that must outlast the longest lockstep wait (`lockstep_wait_s`).
"""

from __future__ import annotations

POLL_S = 0.05  # longest single spin; liveness of the node is checked this often
READY_POLL_S = 0.005  # spins while waiting for the graph, whose changes wake no spin
MIN_GRACE_S = 0.002  # wait for a Bool after the String while the order is unknown
WARM_UP_RETRY_S = 0.5  # resend the first scan (or a warm-up scan) this often until answered
BOOL_DISCOVERY_S = 0.25  # before the first scan: for a Bool writer the graph does not show yet
FIRST_RETRY_MAX_S = 2.0  # the first scan's resends back off up to this interval
# Once ready, for discovery to name the node reading the scans (Observer.scan_readers_named);
# a participant that never names itself (no ROS node) is sent its first scan after this.
NAMED_WAIT_S = 0.5
CATCH_UP_S = 2.0  # after a missed deadline, wait this long (at least) for the late answer


def catch_up_s(deadline_s: float) -> float:
    """After a missed deadline of `deadline_s`: how long the late answer is waited for."""
    return max(CATCH_UP_S, 3 * deadline_s)


def lockstep_wait_s(scan_timeout: float) -> float:
    """The longest a lockstep exchange waits for one scan's answer: the deadline, then
    the catch-up wait."""
    return scan_timeout + catch_up_s(scan_timeout)
