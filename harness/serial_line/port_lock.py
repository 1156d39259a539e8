"""One run at a time per serial port, across threads, processes and pytest workers.

Two runs on one USB-UART would judge each other's revolutions. The lock is
an exclusive ``flock`` on a temp file named after the device's real path
(by-id and ttyUSB0 are one port), not on the device (opening a tty toggles
DTR); the kernel frees it when its holder dies. Re-entrant within a process:
the plugin holds the port for a test and its link takes it again.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from urllib.parse import quote

from harness.errors import ConfigError
from harness.holder_lock import Held, HolderLock, shared_folder, take

__all__ = ["DEFAULT_WAIT_S", "LOCK_DIR", "PortLock", "hold_port"]

LOCK_DIR = Path(tempfile.gettempdir()) / "fossbot-hil-ports"
#: A run in progress usually lasts longer than this; the default is short so
#: that a mistaken second run says so soon. The pytest plugin waits longer.
DEFAULT_WAIT_S = 10.0


def _lock_file(device: str) -> Path:
    return LOCK_DIR / f"{quote(os.path.realpath(device), safe='')}.lock"


class PortLock:
    """This process's turn on one port, until `release()` (or process exit)."""

    def __init__(self, device: str, lock: HolderLock) -> None:
        self.device = device
        self._lock = lock

    def release(self) -> None:
        """Give the port up; safe to call twice."""
        self._lock.release()

    def __enter__(self) -> PortLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def hold_port(device: str, wait: float = DEFAULT_WAIT_S, *, label: str | None = None) -> PortLock:
    """Take `device`'s lock, waiting at most `wait` s; then a ConfigError naming the holder."""
    label = label or device
    path = _lock_file(device)
    try:
        shared_folder(LOCK_DIR)
        lock = take(path, wait=wait, reentrant=True, shared=True)
    except Held as busy:
        raise ConfigError(
            f"{label}: in use by {busy.holder}; waited {wait:g} s for it to finish"
        ) from None
    except OSError as err:
        raise ConfigError(f"{label}: cannot use the port lock {path}: {err.strerror}") from None
    return PortLock(device, lock)
