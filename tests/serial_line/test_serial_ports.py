"""Ports: a real pty pair, and pyserial on a pty slave standing in for a USB-UART."""

from __future__ import annotations

import errno
import os
import select
import termios
import time

import pytest

from harness.errors import ConfigError, LinkError
from harness.serial_line.ports import PortInfo, PtyPort, SerialPort, list_serial_ports

pytestmark = pytest.mark.timeout(20)


def open_board_end(path: str) -> int:
    """Open the slave the way a board driver would, without touching its settings."""
    return os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)


def read_exactly(fd: int, n: int, timeout: float = 2.0) -> bytes:
    got = bytearray()
    deadline = time.monotonic() + timeout
    while len(got) < n and (left := deadline - time.monotonic()) > 0:
        if select.select([fd], [], [], left)[0]:
            got += os.read(fd, n - len(got))
    return bytes(got)


def collect(port: PtyPort, n: int, timeout: float = 2.0) -> bytes:
    got = bytearray()
    deadline = time.monotonic() + timeout
    while len(got) < n and (left := deadline - time.monotonic()) > 0:
        got += port.read(4096, left)
    return bytes(got)


@pytest.fixture
def pty():
    port = PtyPort()
    yield port
    port.close()


def test_pty_round_trip_is_8_bit_clean_and_raw(pty: PtyPort) -> None:
    board = open_board_end(pty.slave_path)
    try:
        attrs = termios.tcgetattr(board)
        iflag, oflag, _cflag, lflag = attrs[:4]
        assert not lflag & (termios.ICANON | termios.ECHO | termios.ISIG)
        assert not oflag & termios.OPOST
        assert not iflag & (termios.ICRNL | termios.INLCR | termios.IXON | termios.ISTRIP)

        every_byte = bytes(range(256))
        assert pty.write(every_byte, 1.0) == 256
        assert read_exactly(board, 256) == every_byte  # ^C, ^D, XON/XOFF, CR, LF all survive

        os.write(board, b"a\r\nb\rc\n\x00\xff" + every_byte)
        assert collect(pty, 9 + 256) == b"a\r\nb\rc\n\x00\xff" + every_byte
        assert pty.read(4096, 0.05) == b""  # no echo of what we wrote
    finally:
        os.close(board)


def test_no_reader_yet_is_not_an_error(pty: PtyPort) -> None:
    # The Linux fact the port handles: the master gives EIO while nobody has the slave.
    with pytest.raises(OSError) as raw:
        os.read(pty.fileno(), 1)
    assert raw.value.errno == errno.EIO

    assert pty.peer_present() is False
    start = time.monotonic()
    assert pty.read(4096, 0.1) == b""
    assert 0.09 <= time.monotonic() - start < 1.0
    assert pty.write(b"stale", 0.1) == 0  # nothing queued for a future reader

    board = open_board_end(pty.slave_path)
    try:
        assert pty.peer_present() is True
        assert pty.write(b"hello", 1.0) == 5
        assert read_exactly(board, 5) == b"hello"
    finally:
        os.close(board)
    assert pty.peer_present() is False
    assert pty.read(4096, 0.02) == b""  # the reader left: still not an error


def test_settings_survive_the_board_reopening(pty: PtyPort) -> None:
    for _ in range(2):
        board = open_board_end(pty.slave_path)
        try:
            assert not termios.tcgetattr(board)[3] & termios.ICANON
            assert pty.write(b"\r\n", 1.0) == 2
            assert read_exactly(board, 2) == b"\r\n"
        finally:
            os.close(board)


def test_bounded_read_returns_empty_on_timeout(pty: PtyPort) -> None:
    board = open_board_end(pty.slave_path)
    try:
        start = time.monotonic()
        assert pty.read(4096, 0.1) == b""
        assert 0.09 <= time.monotonic() - start < 1.0
        assert pty.read(4096, 0.0) == b""
    finally:
        os.close(board)


def test_wake_pipe_cuts_a_read_short(pty: PtyPort) -> None:
    board = open_board_end(pty.slave_path)
    wake_r, wake_w = os.pipe()
    try:
        os.write(wake_w, b"w")
        start = time.monotonic()
        assert pty.read(4096, 5.0, wake_r) == b""
        assert time.monotonic() - start < 1.0
    finally:
        for fd in (board, wake_r, wake_w):
            os.close(fd)


def test_symlink_names_the_slave(tmp_path) -> None:
    link = tmp_path / "ttyLIDAR"
    port = PtyPort(symlink=str(link))
    try:
        assert os.readlink(link) == port.slave_path
        assert port.name == str(link)
    finally:
        port.close()
    assert not link.exists()


def test_serial_port_that_cannot_open_is_a_one_line_config_error(tmp_path) -> None:
    missing = str(tmp_path / "ttyUSB9")
    with pytest.raises(ConfigError) as err:
        SerialPort(missing)
    assert str(err.value) == f"--port {missing}: cannot open: [Errno 2] No such file or directory"


def test_serial_port_that_is_not_a_tty_is_a_config_error(tmp_path) -> None:
    plain = tmp_path / "not-a-tty"
    plain.write_bytes(b"")
    with pytest.raises(ConfigError) as err:
        SerialPort(str(plain))
    assert str(err.value).startswith(f"--port {plain}: cannot open: ")
    assert "\n" not in str(err.value)


@pytest.fixture
def adapter():
    """pyserial on a pty slave stands in for a USB-UART; the master is the far end."""
    far, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    port = SerialPort(path, 115200)
    yield port, far, path
    port.close()
    try:
        os.close(far)
    except OSError:
        pass


def test_serial_port_round_trip_on_a_pty(adapter) -> None:
    port, far, _ = adapter
    assert port.write(b"\xa5\x52", 1.0) == 2
    assert read_exactly(far, 2) == b"\xa5\x52"
    os.write(far, bytes(range(256)))
    got = bytearray()
    deadline = time.monotonic() + 2.0
    while len(got) < 256 and time.monotonic() < deadline:
        got += port.read(4096, 0.1)
    assert bytes(got) == bytes(range(256))
    assert port.read(4096, 0.05) == b""
    assert port.dtr_asserted() is None  # a pty has no modem lines
    assert port.peer_present() is None


def test_serial_port_vanishing_is_a_link_error_within_a_second(adapter) -> None:
    port, far, path = adapter
    os.close(far)  # the adapter is unplugged
    start = time.monotonic()
    with pytest.raises(LinkError) as err:
        port.read(4096, 5.0)
    assert time.monotonic() - start < 1.0
    message = str(err.value)
    assert message.startswith(f"--port {path}: link lost: read failed")
    assert "\n" not in message
    start = time.monotonic()
    with pytest.raises(LinkError, match="link lost: write failed"):
        port.write(b"x" * 64, 5.0)
    assert time.monotonic() - start < 1.0


def test_list_serial_ports_reports_usb_ids(monkeypatch) -> None:
    from serial.tools import list_ports
    from serial.tools.list_ports_common import ListPortInfo

    assert all(isinstance(p, PortInfo) for p in list_serial_ports())  # whatever this host has

    usb = ListPortInfo("/dev/ttyUSB0", skip_link_detection=True)
    usb.vid, usb.pid, usb.serial_number = 0x10C4, 0xEA60, "0001"
    usb.description = "CP2102 USB to UART Bridge Controller"
    plain = ListPortInfo("/dev/ttyS0", skip_link_detection=True)
    monkeypatch.setattr(list_ports, "comports", lambda: [usb, plain])
    ports = list_serial_ports()
    assert ports == [
        PortInfo("/dev/ttyS0", "", None, None),
        PortInfo("/dev/ttyUSB0", "CP2102 USB to UART Bridge Controller", "10C4:EA60", "0001"),
    ]
    assert ports[1].line() == (
        "/dev/ttyUSB0  10C4:EA60 SN=0001  CP2102 USB to UART Bridge Controller"
    )


def test_an_adapters_own_strings_cannot_drive_the_terminal() -> None:
    """USB descriptor strings come from the device: escapes are shown, never sent raw."""
    port = PortInfo("/dev/ttyUSB0", "UART\x1b[2J\x1b]0;pwned\x07", "10C4:EA60", "\x1b[31m1")
    line = port.line()
    assert line.isprintable()
    assert "\\x1b[2J" in line and "SN=\\x1b[31m1" in line
