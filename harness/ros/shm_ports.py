"""Fast DDS shared-memory ports left half-made by a killed process (pure: no rclpy).

Each port's segment, ``/dev/shm/fastrtps_port<N>``, is created empty, sized, then
marked ready; a process killed between those steps leaves one that every participant
taking the port waits on forever (deaf to SIGINT and SIGTERM). A run clears its
reserved domain's half-made ports before its own participants start. In a domain the
harness chose every unmarked port goes (the run before released it); in one the user
named, other programs may be making a port now or use another mark, so only files
empty for `ABANDONED_AFTER_S` go (making one takes microseconds)."""

from __future__ import annotations

import os
import time
from pathlib import Path

__all__ = ["ABANDONED_AFTER_S", "clear_half_made_ports", "domain_ports"]

SHM_DIR = Path("/dev/shm")
PORT_BASE, DOMAIN_GAIN = 7400, 250  # RTPS's port formula: a domain owns 250 ports
READY = (2).to_bytes(4, "little")  # the segment's first word once it is made
ABANDONED_AFTER_S = 10.0


def domain_ports(domain_id: int) -> range:
    """Every port number the RTPS formula can give a participant of `domain_id`."""
    first = PORT_BASE + DOMAIN_GAIN * domain_id
    return range(first, first + DOMAIN_GAIN)


def _ports_present(shm_dir: Path, ports: range) -> list[int]:
    """The ports of `ports` with a segment in `shm_dir`: one listing of the folder costs
    less than trying to open all 250 (about 0.1 ms against 5-10 ms)."""
    prefix = "fastrtps_port"
    try:
        names = os.listdir(shm_dir)
    except OSError:
        return []
    found = (name[len(prefix) :] for name in names if name.startswith(prefix))
    return sorted(int(n) for n in found if n.isdigit() and int(n) in ports)


def clear_half_made_ports(
    domain_id: int, *, shared: bool, shm_dir: Path = SHM_DIR, now: float | None = None
) -> list[str]:
    """Remove `domain_id`'s half-made port segments; their names. `shared`: other programs
    may be in the domain (an id the user named), so only ones long empty."""
    now = time.time() if now is None else now
    removed = []
    for port in _ports_present(shm_dir, domain_ports(domain_id)):
        path = shm_dir / f"fastrtps_port{port}"
        try:
            with path.open("rb") as segment:
                stat = os.fstat(segment.fileno())
                head = segment.read(len(READY))
        except OSError:  # no such port (the usual case), or not ours to read
            continue
        if shared:
            abandoned = not head and now - stat.st_mtime >= ABANDONED_AFTER_S
        else:
            abandoned = head != READY
        if not abandoned:
            continue
        try:
            path.unlink()
        except OSError:  # another user's file in the shared folder: theirs to clear
            continue
        removed.append(path.name)
    return removed
