"""The real emulators served over a pty, read by the FOSSBot's own client.

The robot reads its A1M8 with the PyPI ``rplidar`` package; here it runs
unchanged in a thread against ``DeviceServer(RplidarDevice)`` over a real
pty, which proves the lockstep start marker end to end: every revolution is
yielded exactly as pushed, one per push, and nothing else. One concession:
a pty has no modem lines, so pyserial's ``setDTR`` (the package calls it to
start the A1's motor) fails with ENOTTY; the client's pyserial is made to
ignore that error, as a pty-only shim.
"""

from __future__ import annotations

import errno
import os
import queue
import select
import threading

import pytest
import rplidar  # the FOSSBot's own client (PyPI rplidar): a test dependency

from harness.devices.ldlidar import LdlidarDevice, decode_packets
from harness.devices.revolution import Sample
from harness.devices.rplidar import RplidarDevice
from harness.serial_line.ports import PtyPort
from harness.serial_line.server import DeviceServer

pytestmark = pytest.mark.timeout(30)


@pytest.fixture
def dtr_tolerant_pyserial(monkeypatch):
    """pyserial's setDTR on a pty raises ENOTTY (no modem lines there): ignore just that."""
    import serial.serialposix

    original = serial.serialposix.Serial._update_dtr_state

    def tolerant(self) -> None:
        try:
            original(self)
        except OSError as err:
            if err.errno != errno.ENOTTY:
                raise

    monkeypatch.setattr(serial.serialposix.Serial, "_update_dtr_state", tolerant)


class Client(threading.Thread):
    """``RPLidar(port).iter_scans()`` in a thread; each scan (or the error) to a queue."""

    def __init__(self, path: str) -> None:
        super().__init__(daemon=True)
        self.path = path
        self.scans: queue.Queue = queue.Queue()
        self.lidar = None

    def run(self) -> None:
        try:
            self.lidar = rplidar.RPLidar(self.path, baudrate=115200, timeout=1)
            for scan in self.lidar.iter_scans():
                self.scans.put(scan)
        except Exception as err:  # noqa: BLE001 - handed to the test thread
            self.scans.put(err)

    def next_scan(self, timeout: float = 3.0) -> list[tuple[int, float, float]]:
        item = self.scans.get(timeout=timeout)
        if isinstance(item, Exception):
            raise item
        return item


def revolution(k: int, n: int = 360) -> list[Sample]:
    """One sample a degree; a few no-returns; distances differ per revolution."""
    gap = [i % 50 == 7 for i in range(n)]
    return [
        Sample(i * 360.0 / n, 0.0 if gap[i] else 200.0 + 10.0 * k + i, 0 if gap[i] else 47)
        for i in range(n)
    ]


def as_client_sees(samples: list[Sample]) -> list[tuple[int, float, float]]:
    """What iter_scans yields for these samples: returns only, q6 angles, q2 distances."""
    return [
        (s.quality, round(s.angle_deg * 64) / 64, round(s.distance_mm * 4) / 4)
        for s in samples
        if s.quality > 0 and s.distance_mm > 0
    ]


def run_rplidar(next_start: str, pushes: int) -> tuple[list, list, object]:
    port = PtyPort()
    device = RplidarDevice()
    client = Client(port.slave_path)
    try:
        with DeviceServer(device, port, mode="lockstep", next_start=next_start) as server:
            client.start()
            assert server.wait_until(lambda d: d.mode == "scan" and d.motor_on, 5.0)
            pushed, seen = [], []
            for k in range(pushes):
                rev = revolution(k)
                server.send_revolution(rev, k)
                pushed.append(rev)
                seen.append(client.next_scan())  # lockstep: it comes before the next push
            with pytest.raises(queue.Empty):
                client.next_scan(timeout=0.3)  # and nothing else comes
            stats = server.stats()
    finally:
        port.close()  # the client's next read fails and its thread ends
        client.join(3.0)
    return pushed, seen, stats


@pytest.mark.usefixtures("dtr_tolerant_pyserial")
def test_rplidar_client_gets_every_revolution_exactly_with_extra_marker() -> None:
    pushed, seen, stats = run_rplidar("extra", pushes=4)
    for rev, scan in zip(pushed, seen, strict=True):
        assert scan == as_client_sees(rev)
    assert stats.markers_sent == 4
    assert stats.requests_seen >= 3  # MOTOR_PWM, GET_HEALTH, SCAN


@pytest.mark.usefixtures("dtr_tolerant_pyserial")
def test_rplidar_client_with_replace_marker_loses_each_first_sample() -> None:
    pushed, seen, _ = run_rplidar("replace", pushes=3)
    assert seen[0] == as_client_sees(pushed[0])
    for rev, scan in zip(pushed[1:], seen[1:], strict=True):
        assert scan == as_client_sees(rev[1:])  # the marker (no return) took its place


def ld_frames(samples: list[Sample]) -> list[list[Sample]]:
    """Frames as the LDROBOT driver cuts them: a new one where < 20 deg follows > 340 deg."""
    frames: list[list[Sample]] = [[]]
    last = 0.0
    for s in samples:
        if s.angle_deg < 20.0 and last > 340.0:
            frames.append([])
        frames[-1].append(s)
        last = s.angle_deg
    return frames


@pytest.mark.parametrize("next_start", ["extra", "replace"])
def test_ld06_lockstep_frames_close_at_the_marker(next_start: str) -> None:
    port = PtyPort()
    board = open_board(port.slave_path)
    n = 450  # 37 packets and 6 samples: the 6 wait in the encoder for a next packet
    revs = [[Sample(i * 360.0 / n, 300.0 + 5 * k + i, 200) for i in range(n)] for k in range(3)]
    stream = bytearray()
    try:
        with DeviceServer(LdlidarDevice(), port, baudrate=230400, next_start=next_start) as server:
            assert server.unit_samples == 12
            for k, rev in enumerate(revs):
                m = server.marker_samples  # the marker that stands before this revolution
                server.send_revolution(rev, k)
                assert server.wait_idle(3.0)
                # The marker completes the packet the encoder holds open: 450 % 12
                # leaves 6 open in "extra"; in "replace" it alternates 6 and 12.
                assert server.marker_samples == (6 if next_start == "extra" or k % 2 == 0 else 12)
                stream += read_available(board)
                samples, bad = decode_packets(bytes(stream))
                assert bad == 0
                frames = ld_frames(samples)
                assert len(frames) == k + 2  # frame k closed: the marker's 0 deg followed 359.2
                distances = [s.distance_mm for s in rev]
                angles = [s.angle_deg for s in rev]
                if next_start == "extra":  # the previous marker, then the whole revolution
                    distances, angles = [0.0] * m + distances, angles[:m] + angles
                else:  # the previous marker stood in for the first m samples
                    distances = [0.0] * m + distances[m:]
                assert [s.distance_mm for s in frames[k]] == distances
                assert [s.angle_deg for s in frames[k]] == pytest.approx(angles, abs=0.011)
    finally:
        os.close(board)
        port.close()


def open_board(path: str) -> int:
    return os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)


def read_available(fd: int, quiet_s: float = 0.1) -> bytes:
    got = bytearray()
    while select.select([fd], [], [], quiet_s)[0]:
        got += os.read(fd, 65536)
    return bytes(got)
