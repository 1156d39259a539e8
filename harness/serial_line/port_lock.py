"""One run at a time per serial port, across threads, processes and pytest workers.

Two runs driving one USB-UART would interleave their bytes and each judge
the other's revolutions. So whoever opens a physical port first takes a
lock named after it, and later runs wait their turn (bounded) or give up
with a line saying who holds it.

The lock is an exclusive ``flock`` on a file in the temp folder, not on the
device: opening a tty has side effects (DTR toggles, some boards reset).
The file is named after the device's real path, so ``/dev/serial/by-id/...``
and ``/dev/ttyUSB0`` are one port. The kernel frees the lock when its holder
dies, so a crashed run never leaves a port locked. Within one process the
lock is re-entrant: the pytest plugin holds the port for a whole test and
the link it runs takes it again when it opens the port.
"""

from __future__ import annotations

import fcntl
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from urllib.parse import quote

from harness.errors import ConfigError

__all__ = ["DEFAULT_WAIT_S", "LOCK_DIR", "PortLock", "hold_port"]

LOCK_DIR = Path(tempfile.gettempdir()) / "fossbot-hil-ports"
#: A run in progress usually lasts longer than this; the default is short so
#: that a mistaken second run says so soon. The pytest plugin waits longer.
DEFAULT_WAIT_S = 10.0
POLL_S = 0.05  # the kernel has no timed flock: retry this often until the deadline

_guard = threading.Lock()
_held: dict[str, tuple[int, int]] = {}  # lock file -> (descriptor, holders in this process)


def _lock_file(device: str) -> Path:
    return LOCK_DIR / f"{quote(os.path.realpath(device), safe='')}.lock"


def _open_shared(path: Path) -> int:
    """The lock file, readable and writable by every user of this machine."""
    if not LOCK_DIR.is_dir():
        LOCK_DIR.mkdir(parents=True, exist_ok=True)
        try:
            LOCK_DIR.chmod(0o1777)  # like /tmp: anyone may add a lock, only owners remove
        except OSError:
            pass
    handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        os.fchmod(handle, 0o666)
    except OSError:
        pass  # another user's file: it is already shared
    return handle


def _holder(handle: int) -> str:
    """Who holds the lock, as its holder wrote it: "pid 123 (fossbot-hil run), 12 s"."""
    try:
        text = os.pread(handle, 512, 0).decode(errors="replace").split("\n")
    except OSError:
        return "another run"
    if len(text) < 2 or not text[0].isdigit():
        return "another run"
    try:
        held = f", for {time.time() - float(text[1]):.0f} s"
    except ValueError:
        held = ""
    command = f" ({text[2]})" if len(text) > 2 and text[2] else ""
    return f"pid {text[0]}{command}{held}"


def _who() -> str:
    """This process, for the message another run shows while it waits."""
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker:
        return f"pytest worker {worker}"
    return " ".join([os.path.basename(sys.argv[0]), *sys.argv[1:3]])[:120].replace("\n", " ")


class PortLock:
    """This process's turn on one port, until `release()` (or process exit)."""

    def __init__(self, device: str, key: str) -> None:
        self.device = device
        self._key: str | None = key

    def release(self) -> None:
        """Give the port up; safe to call twice."""
        key, self._key = self._key, None
        if key is None:
            return
        with _guard:
            handle, count = _held[key]
            if count > 1:
                _held[key] = (handle, count - 1)
                return
            del _held[key]
            os.close(handle)  # closing the only descriptor drops the flock

    def __enter__(self) -> PortLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def hold_port(device: str, wait: float = DEFAULT_WAIT_S, *, label: str | None = None) -> PortLock:
    """Take `device`'s lock, waiting at most `wait` seconds for the run that holds it.

    ConfigError after the wait names the holder; `label` (e.g. "--port
    /dev/ttyUSB0") starts the message.
    """
    label = label or device
    path = _lock_file(device)
    key = str(path)
    with _guard:
        if key in _held:
            handle, count = _held[key]
            _held[key] = (handle, count + 1)
            return PortLock(device, key)
    try:
        handle = _open_shared(path)
    except OSError as err:
        raise ConfigError(f"{label}: cannot use the port lock {path}: {err.strerror}") from None
    deadline = time.monotonic() + max(0.0, wait)
    while True:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            break
        except BlockingIOError:
            if time.monotonic() >= deadline:
                holder = _holder(handle)
                os.close(handle)
                raise ConfigError(
                    f"{label}: in use by {holder}; waited {wait:g} s for it to finish"
                ) from None
            time.sleep(POLL_S)  # polling a bounded condition, not synchronising
    command = _who()
    os.ftruncate(handle, 0)
    os.pwrite(handle, f"{os.getpid()}\n{time.time():.3f}\n{command}\n".encode(), 0)
    with _guard:
        _held[key] = (handle, 1)
    return PortLock(device, key)
