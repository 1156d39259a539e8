"""Reserve a ROS_DOMAIN_ID per run so parallel runs never see each other.

As in ROS 2's domain_coordinator, a reservation is an OS resource the kernel frees
when the process dies (an exclusive ``flock`` on one file per id, ``harness.holder_lock``,
which names the holder for a refused run), so a crash never leaks an id. An explicit
id (``--domain-id``, a board's) is reserved in the same files: a second run asking for
an id another holds is refused with a ConfigError naming the holder, as the two would
judge each other's messages; within a process it may be taken again (the plugin
reserves, the link takes it by number). Only other fossbot-hil runs here are excluded:
joining a board's graph over the network is what an explicit id is for. Once reserved,
the domain's half-made shared-memory ports are cleared (``shm_ports``)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from harness.errors import ConfigError, LinkError
from harness.holder_lock import Held, HolderLock, shared_folder, take
from harness.ros.shm_ports import clear_half_made_ports

# 0 is everyone's default; ids above 101 can collide with ephemeral ports on Linux.
FIRST_ID, LAST_ID = 1, 101
LOCK_DIR = Path(tempfile.gettempdir()) / "fossbot-hil-domains"


class NoFreeDomain(LinkError):
    """Every automatic id is held (by this machine's runs): a moment later one may be free."""


class DomainReservation:
    """An id held until `release()` (or process exit)."""

    def __init__(self, domain_id: int, lock: HolderLock | None) -> None:
        self.domain_id = domain_id
        self._lock = lock

    def fileno(self) -> int | None:
        """The lock's descriptor (None: held by a process that started us, or released),
        for the run's processes to hold with us."""
        return None if self._lock is None else self._lock.fileno()

    def release(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def __enter__(self) -> DomainReservation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def lock_file(domain_id: int) -> Path:
    """The id's lock file, in a folder every user's runs on this machine share."""
    return shared_folder(LOCK_DIR) / f"{domain_id}.lock"


def _try_lock(domain_id: int) -> HolderLock | None:
    """The id's lock, or None when another run (or this process) holds it; a file we may not
    write counts as taken (one id fewer beats a crash)."""
    try:
        return take(lock_file(domain_id), shared=True)
    except (Held, OSError):
        return None


_reservations = 0


def reserve_domain(preferred: int | None = None) -> DomainReservation:
    """A free domain id, or `preferred` (an explicit id) if no other run holds it. Each
    automatic reservation in a process starts one id further on: a domain used a moment
    ago may still hold the last run's announcements, and rediscovery has taken seconds."""
    global _reservations
    if preferred is not None:
        return _reserve_explicit(preferred)
    span = LAST_ID - FIRST_ID + 1
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw")
    start = (os.getpid() + 17 * int(worker or 0) + _reservations) % span
    _reservations += 1
    for offset in range(span):
        domain_id = FIRST_ID + (start + offset) % span
        lock = _try_lock(domain_id)
        if lock is not None:
            clear_half_made_ports(domain_id, shared=False)
            return DomainReservation(domain_id, lock)
    raise NoFreeDomain(f"no free ROS domain id in {FIRST_ID}..{LAST_ID}: too many runs at once")


def _reserve_explicit(domain_id: int) -> DomainReservation:
    """Take `domain_id` (again, within this process); ConfigError naming another holder."""
    path = lock_file(domain_id)
    try:
        lock = take(path, reentrant=True, shared=True)
    except Held as busy:
        if busy.holder.pid is not None and busy.holder.pid in _ancestors():
            return DomainReservation(domain_id, None)  # our starter's reservation
        raise ConfigError(
            f"ROS domain {domain_id} is in use by {busy.holder}: two runs in one domain "
            "would judge each other's messages; wait for it, or choose another domain id "
            "(or none: each run then reserves a free one)"
        ) from None
    except OSError as err:
        raise ConfigError(
            f"ROS domain {domain_id}: cannot use its lock file {path}: {err.strerror or err}"
        ) from None
    clear_half_made_ports(domain_id, shared=True)  # a named id: others may be in it
    return DomainReservation(domain_id, lock)


def _ancestors(limit: int = 64) -> set[int]:
    """The pids of this process's parent, its parent, and so on (init excluded)."""
    found: set[int] = set()
    pid = os.getppid()
    while pid > 1 and pid not in found and len(found) < limit:
        found.add(pid)
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
        except OSError:
            break
        pid = int(stat.rsplit(")", 1)[1].split()[1])  # after the name: state, ppid
    return found


def discovery_environment(*, network: bool) -> dict[str, str]:
    """Environment that keeps discovery on this machine unless a network is wanted."""
    return {} if network else {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
