"""`fossbot-hil emulate` explains itself to real clients on a real pty.

`-v` logs each request a client sent and what was answered; Ctrl-C
(SIGINT) or SIGTERM is a normal end, with a summary whose counts match
what the client did; a client at the wrong baud, sending garbage or made
for another device type is counted and logged; with no client the summary
says so instead of reading like success.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
import serial
from emulator_process import Emulator
from pty_clients import tolerate_missing_dtr_on_pty

from harness.devices import rplidar as rp

pytestmark = pytest.mark.timeout(90)

SHORT = (
    "description: Two seconds facing a wall.\n"
    "obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]\n"
    "motion: {segments: [{until: {duration: 2.0}}]}\n"
)


@pytest.fixture
def emulators() -> Iterator[list[Emulator]]:
    """Emulators a test starts; killed at its end if still running."""
    started: list[Emulator] = []
    yield started
    for emulator in started:
        emulator.close()


def start(emulators: list[Emulator], *args: str, cwd: Path | None = None) -> Emulator:
    emulator = Emulator(*args, cwd=cwd)
    emulators.append(emulator)
    return emulator


def test_sigint_mid_stream_ends_with_the_counts_the_client_saw(emulators) -> None:
    """The rplidar package reads 3 scans; -v names each request; SIGINT: exit 0, counts match."""
    from rplidar import RPLidar

    tolerate_missing_dtr_on_pty()
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    lidar = RPLidar(emulator.port, timeout=3)
    try:
        assert lidar.get_info()["model"] == 0x18
        scans = 0
        for _scan in lidar.iter_scans():
            scans += 1
            if scans == 3:
                break
        lidar.stop()  # STOP while the 4th revolution streams: it is cut short
    finally:
        lidar.disconnect()
    emulator.wait_for(r"request STOP  A5 25 .*scan stopped", 10)
    assert emulator.finish(signal.SIGINT) == 0, emulator.text()
    log = emulator.text()
    assert "request GET_INFO  A5 50  -> answered 27 bytes: A5 5A 14 00 00 00 04 18" in log
    assert "request SCAN  A5 20  -> answered 7 bytes: A5 5A 05 00 00 40 81" in log
    assert "a client opened" in log and "] error " not in log
    # rplidar 0.9.2 sends MOTOR_PWM in its constructor and again before scanning,
    # GET_HEALTH before scanning, then SCAN; stop() sends STOP.
    requests = emulator.summary_field("requests")
    assert requests == "MOTOR_PWM 2, GET_INFO 1, GET_HEALTH 1, SCAN 1, STOP 1"
    assert log.count("] request ") == 6
    assert "stopped by SIGINT" in log and "served" in log
    revolutions = emulator.summary_field("revolutions")
    whole = int(revolutions.split(" served whole")[0].split(", ")[-1])
    cut = int(revolutions.split(" cut short")[0].split(", ")[-1])
    # The client yields revolution k when revolution k+1 starts: 3 scans, 4 started.
    assert whole >= scans and whole + cut == scans + 1, revolutions
    assert emulator.summary_field("errors") == "none"
    assert emulator.summary_field("client") == "read from the device"


def test_adafruit_client_requests_are_logged_and_sigterm_is_a_normal_end(emulators) -> None:
    """Adafruit's client: its requests show in -v; SIGTERM gives exit 0 and the summary."""
    from adafruit_rplidar import RPLidar

    tolerate_missing_dtr_on_pty()
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    lidar = RPLidar(None, emulator.port, timeout=3)
    try:
        assert lidar.health[0] == "Good"
        for _n, _scan in zip(range(2), lidar.iter_scans(), strict=False):
            pass
        lidar.stop()
    finally:
        lidar.disconnect()
    emulator.wait_for(r"request STOP", 10)
    assert emulator.finish(signal.SIGTERM) == 0, emulator.text()
    log = emulator.text()
    assert "request GET_HEALTH  A5 52  -> answered 10 bytes" in log
    assert "request SCAN  A5 20" in log
    assert "stopped by SIGTERM" in log
    # Its health property asks each time it is read, and once more before scanning.
    assert emulator.summary_field("requests") == "MOTOR_PWM 2, GET_HEALTH 2, SCAN 1, STOP 1"


def test_wrong_baud_and_garbage_are_counted_and_logged(emulators) -> None:
    """A client at 9600 baud sending noise and a bad checksum: each error logged and counted."""
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    with serial.Serial(emulator.port, 9600, timeout=3) as client:
        emulator.wait_for(r"error wrong_baud: the client set its line to 9600 baud", 10)
        bad = bytearray(rp.encode_request(rp.CMD_GET_LIDAR_CONF, b"\x70\x00\x00\x00"))
        bad[-1] ^= 0xFF
        client.write(b"\x00\x13\x37" + bytes(bad) + rp.encode_request(rp.CMD_GET_HEALTH))
        assert len(client.read(10)) == 10  # the good request behind them is answered
    emulator.wait_for(r"error garbage_bytes  00 13 37", 5)
    assert emulator.finish(signal.SIGINT) == 0
    log = emulator.text()
    assert "error bad_checksum GET_LIDAR_CONF" in log and "request dropped" in log
    assert emulator.summary_field("requests") == "GET_HEALTH 1"
    assert emulator.summary_field("errors") == "bad_checksum 1, garbage_bytes 3, wrong_baud 1"


def test_an_rplidar_driver_on_an_ld19_is_told_it_has_the_wrong_device(emulators) -> None:
    """RPLIDAR requests to the LD19 emulator are counted and named as another device's."""
    emulator = start(emulators, "ldlidar", "--scenario", "approach_wall", "-v")
    with serial.Serial(emulator.port, 230400, timeout=3) as client:
        client.write(rp.encode_request(rp.CMD_GET_INFO))
        emulator.wait_for(r"error ignored_host_bytes  A5 50 .*RPLIDAR driver", 10)
    assert emulator.finish(signal.SIGINT) == 0
    assert emulator.summary_field("errors") == "ignored_host_bytes 2"
    assert "LD06/LD19, which takes no commands" in emulator.summary_field("likely cause")


def test_without_a_client_the_summary_does_not_read_like_success(emulators, tmp_path) -> None:
    """Nobody opens the pty: status lines say so, the end says NO CLIENT, and exit is 1."""
    (tmp_path / "short.yaml").write_text(SHORT)
    emulator = start(emulators, "rplidar", "--scenario", "short.yaml", cwd=tmp_path)
    assert emulator.finish(None) == 1, emulator.text()
    log = emulator.text()
    assert "NO CLIENT: nothing opened" in log and "served whole" in log
    assert emulator.summary_field("client") == "never connected"
    assert "nothing opened" in emulator.summary_field("likely cause")


def test_sigint_without_a_client_is_a_normal_end_that_says_no_client(emulators) -> None:
    """Ctrl-C is how emulate is stopped: exit 0, and still no claim that anything was served."""
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall")
    assert emulator.finish(signal.SIGINT) == 0
    assert "stopped by SIGINT" in emulator.text() and "NO CLIENT" in emulator.text()
