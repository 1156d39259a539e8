"""Fast DDS shared-memory ports left half-made by a killed process (pure: no rclpy).

Fast DDS gives each port of a domain a shared-memory segment,
``/dev/shm/fastrtps_port<N>``, made by whichever participant needs it first:
the file is created empty, sized, then marked ready. A process killed
between those steps (a node or worker SIGKILLed mid-start) leaves the file
empty or never marked, and from then on every participant of that domain
that takes the same port waits for it to be marked, forever: its process no
longer answers SIGINT or SIGTERM. A node "never becomes ready"; a harness
participant hangs its whole run.

A run clears the half-made ports of the domain it reserved before any
participant of its own starts there; the next participant that needs such a
port makes it again. In a domain the harness chose, every port not marked
ready goes: whatever a run before left there is gone once its reservation
could be taken, so even a port that was whole is only made again. A domain
the user named is shared with other programs, which may be making a port
right now or use another Fast DDS whose mark differs: there only files that
have stayed empty for `ABANDONED_AFTER_S` go (making one takes microseconds).
"""

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
