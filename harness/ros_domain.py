"""Reserve a ROS_DOMAIN_ID per run so parallel runs never see each other.

Like ROS 2's domain_coordinator, a reservation is held by an open OS
resource that the kernel frees when the process dies, so a crashed run
never leaks an id: here an exclusive ``flock`` on one file per id.
"""

from __future__ import annotations

import fcntl
import os
import tempfile
from pathlib import Path

from harness.errors import LinkError

# 0 is everyone's default; ids above 101 can collide with ephemeral ports on Linux.
FIRST_ID, LAST_ID = 1, 101
LOCK_DIR = Path(tempfile.gettempdir()) / "fossbot-hil-domains"


class DomainReservation:
    """An id held until `release()` (or process exit)."""

    def __init__(self, domain_id: int, handle: int | None) -> None:
        self.domain_id = domain_id
        self._handle = handle

    def release(self) -> None:
        if self._handle is not None:
            os.close(self._handle)
            self._handle = None

    def __enter__(self) -> DomainReservation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def _lock_dir() -> Path:
    """The shared folder of lock files: sticky and world-writable like /tmp, so
    every user's runs on this machine take ids from the same pool."""
    if not LOCK_DIR.is_dir():
        LOCK_DIR.mkdir(parents=True, exist_ok=True)
        try:
            os.chmod(LOCK_DIR, 0o1777)
        except OSError:  # made by another user a moment ago: theirs to set
            pass
    return LOCK_DIR


def _try_lock(domain_id: int) -> int | None:
    """A locked handle on the id's file, or None when another run holds it.

    A file another user made without write access for us counts as taken:
    better one id fewer than a crash.
    """
    path = _lock_dir() / f"{domain_id}.lock"
    try:
        handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except PermissionError:
        return None
    try:
        os.fchmod(handle, 0o666)  # the umask must not lock other users out
    except OSError:
        pass  # not ours: its owner set it
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(handle)
        return None
    return handle


_reservations = 0


def reserve_domain(preferred: int | None = None) -> DomainReservation:
    """A free domain id; `preferred` is taken as given (joining a board's graph).

    Each reservation in a process starts one id further on: a domain used a
    moment ago may still hold what the last run's participants announced,
    and rediscovery there has been seen to take seconds.
    """
    global _reservations
    if preferred is not None:
        return DomainReservation(preferred, None)
    span = LAST_ID - FIRST_ID + 1
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw")
    start = (os.getpid() + 17 * int(worker or 0) + _reservations) % span
    _reservations += 1
    for offset in range(span):
        domain_id = FIRST_ID + (start + offset) % span
        handle = _try_lock(domain_id)
        if handle is not None:
            return DomainReservation(domain_id, handle)
    raise LinkError(f"no free ROS domain id in {FIRST_ID}..{LAST_ID}: too many runs at once")
