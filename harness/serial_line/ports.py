"""Byte pipes the emulated LIDAR talks through: a pty pair or a real USB-UART.

Every read and write is bounded, so the server thread always notices its
stop; a port that breaks is a ``LinkError``, one that cannot be opened a
``ConfigError`` (the user named it).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import select
import termios
import time
import tty
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Literal

from harness.errors import ConfigError, LinkError, one_line
from harness.option_names import named
from harness.serial_line.modem_lines import ModemLines, client_environment, shell_exports
from harness.serial_line.port_lock import DEFAULT_WAIT_S, PortLock, hold_port

_NO_PEER_STEP_S = 0.01  # how often a pty without a reader is re-checked
# termios speed constants (B9600, ...) and the rates they stand for.
_BAUD_OF_SPEED = {
    getattr(termios, f"B{rate}"): rate
    for rate in (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)
    if hasattr(termios, f"B{rate}")
}


def _one_line(err: BaseException) -> str:
    """An OS or pyserial error as one short line ("[Errno 2] No such file or directory")."""
    code = getattr(err, "errno", None)
    if isinstance(code, int) and code > 0:
        return f"[Errno {code}] {os.strerror(code)}"
    return one_line(err, limit=1000)


class DevicePort(ABC):
    """The device side of a serial line; `wake` (a pipe's read end) cuts a read short."""

    name: str
    #: True where the hardware sends at the baud rate (a write then takes line time).
    paced_by_hardware: bool = False

    @abstractmethod
    def read(self, max_bytes: int = 4096, timeout: float = 0.0, wake: int | None = None) -> bytes:
        """Host bytes that arrived within `timeout` s (b"" if none, or if woken)."""

    @abstractmethod
    def write(self, data: bytes, timeout: float = 0.0) -> int:
        """Write what the line accepts within `timeout` s; the count written (may be short)."""

    @abstractmethod
    def dtr_asserted(self) -> bool | None:
        """The board's DTR line, or None where it cannot be observed."""

    def peer_present(self) -> bool | None:
        """Whether something has the other end open, or None where it cannot be known."""
        return None

    def host_baud(self) -> int | None:
        """The baud rate the host set on its end, or None where it cannot be seen."""
        return None

    @abstractmethod
    def close(self) -> None:
        """Release the port; safe to call twice."""

    def __enter__(self) -> DevicePort:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class PtyPort(DevicePort):
    """A pseudo-terminal: the harness holds the master, the board opens ``slave_path``.

    The slave is set raw before it is closed (Linux keeps that for later
    openers). No reader shows as POLLHUP (reads give EIO): not an error, and
    ``write`` takes nothing then, or the bytes would greet the next opener as
    stale input. Ptys ignore the baud rate.

    A pty has no modem lines: a client run with ``client_environment()`` sends
    its DTR and RTS to ``modem``. ``dtr_asserted`` is None until a client set
    it (one without the shim: the motor simply runs) and deasserted once it
    closed the port, as a tty does; ``on_modem_change(line, asserted)`` hears each.
    """

    def __init__(self, *, symlink: str | None = None) -> None:
        master, slave = os.openpty()
        try:
            tty.setraw(slave)
            self.slave_path = os.ttyname(slave)
        finally:
            os.close(slave)
        fcntl.fcntl(master, fcntl.F_SETFL, fcntl.fcntl(master, fcntl.F_GETFL) | os.O_NONBLOCK)
        try:
            self.modem: ModemLines | None = ModemLines()
        except OSError as err:
            os.close(master)
            raise ConfigError(
                f"{self.slave_path}: cannot make the socket its modem lines arrive on: "
                f"{_one_line(err)}"
            ) from None
        self.on_modem_change: Callable[[str, bool], None] | None = None
        self._fd: int | None = master
        self.symlink = symlink
        if symlink is not None:
            try:
                if os.path.islink(symlink):
                    os.unlink(symlink)
                os.symlink(self.slave_path, symlink)
            except OSError as err:
                self.close()
                reason = _one_line(err)
                raise ConfigError(f"--pty-link {symlink}: cannot create: {reason}") from None
        self.name = symlink or self.slave_path

    def fileno(self) -> int:
        if self._fd is None:
            raise LinkError(f"{self.name}: pty is closed")
        return self._fd

    def _revents(self) -> int:
        # A fresh poll object each time: one shared by threads refuses concurrent use.
        poller = select.poll()
        poller.register(self.fileno(), select.POLLIN)
        events = 0
        for _, revents in poller.poll(0):
            events |= revents
        if events & select.POLLNVAL:
            raise LinkError(f"{self.name}: pty master is no longer valid")
        return events

    def peer_present(self) -> bool:
        return not self._revents() & select.POLLHUP

    def read(self, max_bytes: int = 4096, timeout: float = 0.0, wake: int | None = None) -> bytes:
        fd = self.fileno()
        deadline = time.monotonic() + max(0.0, timeout)
        waits = [fd] if wake is None else [fd, wake]
        while True:
            left = deadline - time.monotonic()
            revents = self._revents()
            if revents & select.POLLHUP and not revents & select.POLLIN:
                # No reader: the master polls as ready forever, so wait on the
                # wake pipe alone, in short steps, until someone opens the slave.
                if left <= 0:
                    return b""
                alone = [] if wake is None else [wake]
                if select.select(alone, [], [], min(left, _NO_PEER_STEP_S))[0]:
                    return b""
                continue
            ready = select.select(waits, [], [], max(0.0, left))[0]
            if fd in ready:
                try:
                    data = os.read(fd, max_bytes)
                except BlockingIOError:
                    data = b""
                except OSError as err:
                    if err.errno != errno.EIO:  # EIO: the reader went away just now
                        raise LinkError(f"{self.name}: read failed: {_one_line(err)}") from None
                    data = b""
                if data:
                    return data
            if (wake is not None and wake in ready) or time.monotonic() >= deadline:
                return b""

    def write(self, data: bytes, timeout: float = 0.0) -> int:
        fd = self.fileno()
        if not data or not self.peer_present():
            return 0
        deadline = time.monotonic() + max(0.0, timeout)
        done = 0
        view = memoryview(data)
        while done < len(data):
            try:
                done += os.write(fd, view[done:])
                continue
            except BlockingIOError:
                pass
            except OSError as err:
                if err.errno == errno.EIO:  # the reader closed mid-write
                    return done
                raise LinkError(f"{self.name}: write failed: {_one_line(err)}") from None
            left = deadline - time.monotonic()
            if left <= 0:
                break
            select.select([], [fd], [], left)
        return done

    def dtr_asserted(self) -> bool | None:
        """The DTR the client last set through the modem shim; None until one did."""
        self._poll_modem()
        return self.modem.dtr if self.modem is not None else None

    def _poll_modem(self) -> None:
        modem = self.modem
        if modem is None:
            return
        changes = modem.poll()
        if (modem.dtr is not None or modem.rts is not None) and not self.peer_present():
            changes += modem.hang_up()
        if self.on_modem_change is not None:
            for line, asserted in changes:
                self.on_modem_change(line, asserted)

    def client_environment(self, environ: Mapping[str, str] | None = None) -> dict[str, str]:
        """What a client needs for its DTR/RTS calls on ``slave_path`` to reach this port."""
        return client_environment(self.slave_path, self._channel(), environ)

    def client_exports(self) -> str:
        """``client_environment`` as a line for a user to paste into a POSIX shell."""
        return shell_exports(self.slave_path, self._channel())

    def _channel(self) -> str | None:
        if self._fd is None or self.modem is None:
            raise LinkError(f"{self.name}: pty is closed")
        return self.modem.path

    def host_baud(self) -> int | None:
        """The baud the board's driver set (a pty shares its termios); None if not a standard one.

        A wrong baud works on a pty and fails on a cable: this is how the emulator tells.
        """
        try:
            speed = termios.tcgetattr(self.fileno())[5]
        except termios.error:
            return None
        return _BAUD_OF_SPEED.get(speed)

    def close(self) -> None:
        fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)
        modem, self.modem = self.modem, None
        if modem is not None:
            modem.close()
        if self.symlink is not None and os.path.islink(self.symlink):
            with contextlib.suppress(OSError):
                if os.readlink(self.symlink) == self.slave_path:
                    os.unlink(self.symlink)


class SerialPort(DevicePort):
    """A real USB-UART opened with pyserial, only because the user named it.

    Wiring: board TX -> adapter RX, adapter TX -> board RX, GND, and the
    board's DTR -> DSR (or CTS, ``dtr_input="cts"``): the A1's motor follows it.
    The hardware paces the bytes; a vanished adapter is a ``LinkError`` at the
    next operation. The port's lock is taken first (at most `lock_wait` s) and
    the device opened exclusively, so an exclusive holder outside is refused too.
    """

    paced_by_hardware = True

    def __init__(
        self,
        path: str,
        baudrate: int = 115200,
        *,
        dtr_input: Literal["dsr", "cts"] = "dsr",
        write_timeout: float = 0.5,
        lock_wait: float = DEFAULT_WAIT_S,
    ) -> None:
        import serial  # the optional part: only a named port needs pyserial

        self.name = path
        self._label = f"{named('port')} {path}"  # "--port /dev/ttyUSB0" in the CLI
        self._serial_exc: tuple[type[BaseException], ...] = (serial.SerialException, OSError)
        self._timeout_exc = serial.SerialTimeoutException
        if dtr_input not in ("dsr", "cts"):
            raise ConfigError(f"{self._label}: dtr input must be dsr or cts, not {dtr_input!r}")
        self.dtr_input = dtr_input
        self._lock: PortLock | None = hold_port(path, lock_wait, label=self._label)
        try:
            # timeout=0: reads never block inside pyserial; we wait with select.
            self._ser: serial.Serial | None = serial.Serial(
                path, baudrate, timeout=0, write_timeout=write_timeout, exclusive=True
            )
        except (serial.SerialException, OSError, ValueError) as err:
            self._lock.release()
            if "exclusively lock" in str(err):
                raise ConfigError(
                    f"{self._label}: already open elsewhere, with an exclusive lock"
                ) from None
            raise ConfigError(f"{self._label}: cannot open: {_one_line(err)}") from None

    def _port(self):  # noqa: ANN202 - serial.Serial, imported lazily
        if self._ser is None:
            raise LinkError(f"{self._label}: port is closed")
        return self._ser

    def _lost(self, what: str, err: BaseException) -> LinkError:
        return LinkError(f"{self._label}: link lost: {what} failed: {_one_line(err)}")

    def read(self, max_bytes: int = 4096, timeout: float = 0.0, wake: int | None = None) -> bytes:
        ser = self._port()
        try:
            waiting = ser.in_waiting
            if not waiting:
                fd = ser.fileno()
                waits = [fd] if wake is None else [fd, wake]
                ready, _, _ = select.select(waits, [], [], max(0.0, timeout))
                if fd not in ready:
                    return b""
            # Readable but empty means the device is gone: pyserial raises then.
            return ser.read(max(1, min(waiting or ser.in_waiting, max_bytes)))
        except self._serial_exc as err:
            raise self._lost("read", err) from None

    def write(self, data: bytes, timeout: float = 0.0) -> int:
        """All of `data` or LinkError: pyserial cannot say how much a timed-out write sent."""
        ser = self._port()
        if not data:
            return 0
        try:
            return ser.write(data) or 0
        except self._timeout_exc:
            raise LinkError(
                f"{self._label}: link lost: write stalled for {ser.write_timeout} s"
            ) from None
        except self._serial_exc as err:
            raise self._lost("write", err) from None

    def dtr_asserted(self) -> bool | None:
        ser = self._port()
        try:
            return bool(ser.dsr if self.dtr_input == "dsr" else ser.cts)
        except OSError as err:
            if err.errno in (errno.ENOTTY, errno.EINVAL):  # no modem lines (e.g. a pty)
                return None
            raise self._lost("modem-line query", err) from None

    def close(self) -> None:
        ser, self._ser = self._ser, None
        if ser is not None:
            with contextlib.suppress(Exception):  # a vanished port may fail to close: gone anyway
                ser.close()
        lock, self._lock = self._lock, None
        if lock is not None:
            lock.release()  # after closing: the next run never finds the device still open


@dataclass(frozen=True)
class PortInfo:
    """One serial port the OS knows, for ``fossbot-hil ports``."""

    device: str
    description: str
    vid_pid: str | None  # "10C4:EA60" for USB adapters, else None
    serial_number: str | None
    manufacturer: str | None = None

    def line(self) -> str:
        """One row for the terminal; the adapter's own strings go through the sanitiser."""
        from harness.safe_text import for_terminal

        ids = self.vid_pid or "-"
        sn = f" SN={self.serial_number}" if self.serial_number else ""
        return for_terminal(f"{self.device}  {ids}{sn}  {self.description}")


def list_serial_ports() -> list[PortInfo]:
    """The serial ports pyserial can see, sorted by device name (ptys are not listed)."""
    from serial.tools import list_ports

    found = []
    for p in list_ports.comports():
        vid_pid = f"{p.vid:04X}:{p.pid:04X}" if p.vid is not None and p.pid is not None else None
        description = p.description if p.description and p.description != "n/a" else ""
        found.append(PortInfo(p.device, description, vid_pid, p.serial_number, p.manufacturer))
    return sorted(found, key=lambda info: info.device)
