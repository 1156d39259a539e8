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

from harness.devices import ldlidar as ld
from harness.devices import rplidar as rp

pytestmark = pytest.mark.timeout(90)

# The frames lds2d 0.7.0's LD06/LD19 driver sends on start() and stop() (LD14P-style).
LD_START = bytes.fromhex("54 A0 04 00 00 00 00 5E")
LD_STOP = bytes.fromhex("54 A1 04 00 00 00 00 4A")

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
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    # info, 3 scans, then STOP while the 4th revolution streams: it is cut short
    read = emulator.run_client("rplidar", "--ask", "info", "--scans", "3")
    assert read["info"]["model"] == 0x18
    scans = len(read["scans"])
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
    # The client yields revolution k at the next start flag: revolution k+1's, or
    # the one-node start marker sent when k+1 is late at its slot (an underrun),
    # in which case the STOP can come before k+1 starts. 3 scans: 3 whole, and
    # the 4th cut short by the STOP unless the marker ended the 3rd.
    assert scans <= whole <= whole + cut <= scans + 1, revolutions
    assert emulator.summary_field("errors") == "none"
    assert emulator.summary_field("client") == "read from the device"


def test_adafruit_client_requests_are_logged_and_sigterm_is_a_normal_end(emulators) -> None:
    """Adafruit's client: its requests show in -v; SIGTERM gives exit 0 and the summary."""
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    read = emulator.run_client("adafruit", "--ask", "health", "--scans", "2")
    assert read["health"][0] == "Good"
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


def test_without_v_a_status_line_says_client_state_and_what_was_served(emulators) -> None:
    """No -v: no request lines, but a status line (connected, scanning, counts) every 5 s."""
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall")
    client = emulator.start_client("rplidar", "--scans", "0")  # reads on, as a driver does
    try:
        line = emulator.wait_for(r"\| scanning \(standard\) \|", 20)
    finally:
        client.kill()
        client.communicate(timeout=10)
    assert "client: connected at 115200 baud | scanning (standard) | " in line, line
    served = line.split(" | ")[2]
    assert int(served.split(" revolutions")[0]) > 0 and " 0 bytes" not in served, line
    assert line.endswith("| errors 0"), line
    assert emulator.finish(signal.SIGINT) == 0
    assert "] request " not in emulator.text()  # requests are -v's
    assert emulator.summary_field("client") == "read from the device"


def test_an_ld_drivers_command_frames_are_ignored_requests_not_errors(emulators) -> None:
    """lds2d's LD19 driver sends start/stop frames: the LD19 streams on, -v logs them, no error."""
    emulator = start(emulators, "ldlidar", "--scenario", "approach_wall", "-v")
    with serial.Serial(emulator.port, 230400, timeout=3) as client:
        client.write(LD_START)
        emulator.wait_for(r"request LD_START  54 A0 04 00 00 00 00 5E  -> .*ignored", 10)
        data = client.read(4 * ld.PACKET_LEN)
        client.write(LD_STOP)
        emulator.wait_for(r"request LD_STOP", 10)
    samples, bad = ld.decode_packets(data)
    assert samples and bad == 0
    assert emulator.finish(signal.SIGINT) == 0
    assert "] error " not in emulator.text()
    assert emulator.summary_field("requests") == "LD_START 1, LD_STOP 1"
    assert emulator.summary_field("errors") == "none"


def test_an_ld_driver_on_the_a1_is_told_it_has_the_wrong_device(emulators) -> None:
    """An LD19 driver (230400 baud, LD frames) on the A1 emulator: both errors name the LD."""
    emulator = start(emulators, "rplidar", "--scenario", "approach_wall", "-v")
    with serial.Serial(emulator.port, 230400, timeout=3) as client:
        client.write(LD_START)
        emulator.wait_for(r"error garbage_bytes  54 A0 04 .*LDROBOT command frame", 10)
        emulator.wait_for(r"error wrong_baud: the client set its line to 230400 baud", 10)
    assert emulator.finish(signal.SIGINT) == 0
    assert emulator.summary_field("errors") == "garbage_bytes 8, wrong_baud 1"
    likely = emulator.summary_field("likely cause")
    assert "230400 is an LD06/LD19's rate" in likely and "emulate ldlidar" in likely
