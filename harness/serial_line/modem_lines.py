"""A pty's modem lines, as the client's pyserial sets them through the modem shim.

A pty has no DTR or RTS, yet RPLIDAR clients drive the A1's motor with DTR:
``modem_shim/sitecustomize.py`` on the client's PYTHONPATH makes those
calls succeed and sends each change here as a datagram (b"DTR 1").

``FOSSBOT_HIL_MODEM_LINES``: ``PORT=SOCKET`` items separated by
``os.pathsep``, ``PORT`` the port's real path; ``PORT`` alone lets the calls
succeed and go nowhere. The first item naming a port counts.
"""

from __future__ import annotations

import os
import shlex
import shutil
import socket
import tempfile
import weakref
from collections.abc import Mapping
from pathlib import Path

__all__ = [
    "ENV_VAR",
    "SHIM_FOLDER",
    "ModemLines",
    "client_environment",
    "listing_item",
    "shell_exports",
]

ENV_VAR = "FOSSBOT_HIL_MODEM_LINES"
SHIM_FOLDER = Path(__file__).resolve().with_name("modem_shim")  # holds only sitecustomize.py
_SOCKET_NAME = "lines"
_MAX_SOCKET_PATH = 100  # AF_UNIX paths hold 107 bytes on Linux
_LINES = {b"DTR": "dtr", b"RTS": "rts"}


def _socket_base() -> str:
    """Where the private folder goes: the temporary folder, unless its path could
    not name a socket or could not stand in the variable."""
    base = tempfile.gettempdir()
    if len(base) > _MAX_SOCKET_PATH - 40 or os.pathsep in base or "=" in base:
        return "/tmp"
    return base


def _remove_folder(folder: str, owner: int) -> None:
    """Remove `folder` in the process that made it only: a forked child leaves it."""
    if os.getpid() == owner:
        shutil.rmtree(folder, ignore_errors=True)


class ModemLines:
    """The client's DTR and RTS: each None until the client first set it.

    A non-blocking datagram socket in a private (0700) folder: only this user
    can reach it and ``poll`` never waits; a datagram sent to a full queue is lost.
    """

    def __init__(self) -> None:
        self._folder = tempfile.mkdtemp(prefix="fossbot-hil-modem-", dir=_socket_base())
        # Removed by close(), else when this is collected or at interpreter exit.
        self._remove = weakref.finalize(self, _remove_folder, self._folder, os.getpid())
        self.path = os.path.join(self._folder, _SOCKET_NAME)
        self._sock: socket.socket | None = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        try:
            self._sock.setblocking(False)
            self._sock.bind(self.path)
        except OSError:
            self.close()
            raise
        self.dtr: bool | None = None
        self.rts: bool | None = None

    def poll(self) -> list[tuple[str, bool]]:
        """The changes the client sent since the last poll, in order: ("dtr" or "rts", asserted)."""
        changes: list[tuple[str, bool]] = []
        while self._sock is not None:
            try:
                data = self._sock.recv(64)
            except OSError:  # BlockingIOError: nothing more; or closed under us
                break
            line, _, level = data.partition(b" ")
            name = _LINES.get(line)
            if name is None or level not in (b"0", b"1"):
                continue  # not from the shim: ignored
            self._set(name, level == b"1", changes)
        return changes

    def hang_up(self) -> list[tuple[str, bool]]:
        """The client closed the port: its lines drop, as a tty's do (HUPCL); the changes."""
        changes: list[tuple[str, bool]] = []
        for name in ("dtr", "rts"):
            if getattr(self, name) is not None:
                self._set(name, False, changes)
        return changes

    def _set(self, name: str, asserted: bool, changes: list[tuple[str, bool]]) -> None:
        if getattr(self, name) != asserted:
            setattr(self, name, asserted)
            changes.append((name, asserted))

    def close(self) -> None:
        """Close the socket and remove its folder; safe to call twice."""
        sock, self._sock = self._sock, None
        if sock is not None:
            sock.close()
        self._remove()

    def __enter__(self) -> ModemLines:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def listing_item(port_path: str, channel: str | None) -> str:
    """One item of the variable: ``PORT=SOCKET``, or ``PORT`` where nothing listens."""
    for text in (port_path, channel or ""):
        if os.pathsep in text:
            raise ValueError(f"{text!r}: a path in {ENV_VAR} cannot hold {os.pathsep!r}")
    if "=" in port_path:
        raise ValueError(f"{port_path!r}: a port in {ENV_VAR} cannot hold '='")
    return f"{port_path}={channel}" if channel else port_path


def _first(item: str, existing: str | None) -> str:
    """`item` first, then the existing items (without another copy of `item`)."""
    rest = [part for part in (existing or "").split(os.pathsep) if part != item]
    return os.pathsep.join([item, *rest]) if existing else item


def client_environment(
    port_path: str, channel: str | None, environ: Mapping[str, str] | None = None
) -> dict[str, str]:
    """The variables a client needs for its modem-line calls on `port_path` to reach `channel`.

    The shim's folder and the port's item go first; what was there is kept.
    """
    environ = os.environ if environ is None else environ
    return {
        "PYTHONPATH": _first(str(SHIM_FOLDER), environ.get("PYTHONPATH")),
        ENV_VAR: _first(listing_item(port_path, channel), environ.get(ENV_VAR)),
    }


def shell_exports(port_path: str, channel: str | None) -> str:
    """``client_environment`` as one line for a POSIX shell (bash, zsh, sh), keeping
    that shell's own PYTHONPATH and listing, e.g. ``export PYTHONPATH=/…/modem_shim"${…}"``."""

    def kept(name: str) -> str:
        return f'"${{{name}:+{os.pathsep}${name}}}"'

    item = listing_item(port_path, channel)
    return (
        f"export PYTHONPATH={shlex.quote(str(SHIM_FOLDER))}{kept('PYTHONPATH')} "
        f"{ENV_VAR}={shlex.quote(item)}{kept(ENV_VAR)}"
    )
