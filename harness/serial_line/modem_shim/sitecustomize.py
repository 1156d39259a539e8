"""Modem lines for pyserial clients on the harness's emulated port (a pty).

On a pty pyserial's ``setDTR``/``setRTS`` fail with ENOTTY, yet RPLIDAR
clients drive the A1's motor with DTR. Run at start-up from PYTHONPATH (the
``sitecustomize`` hook), this only adds an import hook that wraps
``serial.serialposix.Serial``'s modem-line calls: where pyserial's own code
fails for want of modem lines on a port ``FOSSBOT_HIL_MODEM_LINES`` lists
(format: ``harness.serial_line.modem_lines``), a DTR or RTS change goes to
the port's socket (b"DTR 1") and reading CTS, DSR, RI or CD gives False.
Then the next ``sitecustomize`` on ``sys.path`` runs as it would have.
"""

from __future__ import annotations

import errno
import os
import sys

TYPE_CHECKING = False  # typing itself is not imported at start-up
if TYPE_CHECKING:
    from collections.abc import Callable
    from importlib.machinery import ModuleSpec
    from types import ModuleType
    from typing import Any

ENV_VAR = "FOSSBOT_HIL_MODEM_LINES"
_TARGET = "serial.serialposix"
_MARK = "_fossbot_hil_modem_lines"  # on our finder and on every wrapped function
_NO_LINES = (errno.ENOTTY, errno.EINVAL)  # what the modem ioctls raise on a pty
_GETTERS = ("cts", "dsr", "ri", "cd")


def _port_names(port: object) -> set[str]:
    """The names this open port answers to: its path's real path, and its tty name."""
    names = set()
    portstr = getattr(port, "portstr", None)
    if isinstance(portstr, str) and portstr:
        names.add(os.path.realpath(portstr))
    fd = getattr(port, "fd", None)
    if isinstance(fd, int):
        try:
            names.add(os.ttyname(fd))
        except OSError:
            pass
    return names


def _channel(port: object, err: OSError) -> str | None:
    """The socket listed for `port` when `err` is its missing modem lines ("" if none
    is listed); None when the error stands (another error, or a port not listed)."""
    listing = os.environ.get(ENV_VAR)
    if err.errno not in _NO_LINES or not listing:
        return None
    names = _port_names(port)
    for item in listing.split(os.pathsep):
        path, _, channel = item.partition("=")
        if path and os.path.realpath(path) in names:
            return channel
    return None


def _send(channel: str, message: bytes) -> None:
    """One datagram to `channel`, never blocking: lost if nothing listens."""
    if not channel:
        return
    import socket

    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sock:
            sock.setblocking(False)
            sock.sendto(message, channel)
    except OSError:
        pass


def _setter(original: Callable[[Any], None], line: str) -> Callable[[Any], None]:
    """`original` (``_update_dtr_state``), succeeding on a listed port without the line."""
    state = f"_{line.lower()}_state"

    def update(self: Any) -> None:
        try:
            original(self)
        except OSError as err:
            channel = _channel(self, err)
            if channel is None:
                raise
            _send(channel, f"{line} {int(bool(getattr(self, state, False)))}".encode())

    update.__name__, update.__qualname__ = original.__name__, original.__qualname__
    update.__doc__ = original.__doc__
    setattr(update, _MARK, True)
    return update


def _getter(original: Callable[[Any], bool]) -> Callable[[Any], bool]:
    """`original` (the ``cts`` getter), False on a listed port without modem lines."""

    def get(self: Any) -> bool:
        try:
            return original(self)
        except OSError as err:
            if _channel(self, err) is None:
                raise
            return False

    get.__name__, get.__doc__ = original.__name__, original.__doc__
    setattr(get, _MARK, True)
    return get


def _patch(module: object) -> None:
    """Wrap the modem-line calls of ``module.Serial`` (once, however often it loads)."""
    serial_class = getattr(module, "Serial", None)
    if serial_class is None:
        return
    for name, line in (("_update_dtr_state", "DTR"), ("_update_rts_state", "RTS")):
        original = serial_class.__dict__.get(name)
        if callable(original) and not getattr(original, _MARK, False):
            setattr(serial_class, name, _setter(original, line))
    for name in _GETTERS:
        prop = serial_class.__dict__.get(name)
        if isinstance(prop, property) and prop.fget and not getattr(prop.fget, _MARK, False):
            setattr(serial_class, name, property(_getter(prop.fget), prop.fset, prop.fdel))


class _Loader:
    """The real loader of ``serial.serialposix``, then the patch."""

    def __init__(self, inner: Any) -> None:
        self._inner = inner

    def create_module(self, spec: ModuleSpec) -> ModuleType | None:
        return self._inner.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        self._inner.exec_module(module)
        _patch(module)

    def __getattr__(self, name: str) -> Any:  # get_source, is_package, ...
        return getattr(self._inner, name)


class _Finder:
    """Finds nothing itself: it lets the other finders find ``serial.serialposix``
    and hands its spec back with a loader that patches the module after it ran."""

    _fossbot_hil_modem_lines = True  # _MARK: another copy of this file adds no second one

    def find_spec(
        self, name: str, path: Any = None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if name != _TARGET:
            return None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            if finder is self or find is None:
                continue
            spec = find(name, path, target)
            if spec is not None:
                if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                    spec.loader = _Loader(spec.loader)
                return spec
        return None


def _install() -> None:
    """Add the finder once; patch at once if pyserial is somehow loaded already."""
    if not any(getattr(finder, _MARK, False) for finder in sys.meta_path):
        sys.meta_path.insert(0, _Finder())
    if _TARGET in sys.modules:
        _patch(sys.modules[_TARGET])


def _chain() -> None:
    """Run the ``sitecustomize`` Python would have run without this one.

    Only folders after this one on ``sys.path`` are searched: site found
    this one first, and two copies of it cannot then run each other forever.
    """
    here = os.path.realpath(os.path.dirname(os.path.abspath(__file__)))
    entries = [(entry, os.path.realpath(entry or os.curdir)) for entry in sys.path]
    reals = [real for _, real in entries]
    after = reals.index(here) + 1 if here in reals else 0
    search = [entry for entry, real in entries[after:] if real != here]
    from importlib.machinery import PathFinder

    spec = PathFinder.find_spec("sitecustomize", search)
    if spec is None or spec.loader is None:
        return
    # importlib.util.module_from_spec, without importing importlib.util at start-up.
    module = type(sys)("sitecustomize")
    module.__spec__, module.__loader__ = spec, spec.loader
    if spec.has_location and spec.origin:
        module.__file__ = spec.origin
    if spec.submodule_search_locations is not None:
        module.__path__ = spec.submodule_search_locations
    sys.modules["sitecustomize"] = module
    spec.loader.exec_module(module)


_install()
_chain()
