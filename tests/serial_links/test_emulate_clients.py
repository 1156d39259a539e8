"""`fossbot-hil emulate` read by independent RPLIDAR clients over a real pty.

The `rplidar` package (what FOSSBot code uses) and Adafruit's client must get
device info, health and scans whose angles and distances match the
simulated beams within the A1's quantisation (1/64 degree, 1/4 mm): in
standard mode each sample is reported at the angle its beam was cast.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator

import numpy as np
import pytest
from pty_clients import tolerate_missing_dtr_on_pty

from harness.devices.revolution import device_angle_deg, encode_distances_mm
from harness.runner.settings import RunSettings, fault_profile
from harness.scenario.files import resolve_scenario
from harness.sim.simulation import Simulation

pytestmark = pytest.mark.timeout(90)

SCENARIO = "approach_wall"
ANGLE_TOL_DEG = 1 / 64 + 1e-6
DISTANCE_TOL_MM = 0.25 + 1e-6


def simulated_revolutions() -> list[np.ndarray]:
    """The simulated beams, tick by tick: rows of (device angle of the beam, distance mm)."""
    scenario = resolve_scenario(SCENARIO)
    spec = scenario.lidar_spec
    faults = fault_profile(scenario, RunSettings())
    rng = np.random.default_rng(scenario.seed)
    revolutions = []
    with Simulation(scenario) as sim:
        for tick in sim.ticks():
            scan = faults.emit(tick.truth, spec, rng, stamp=tick.t)
            angles = np.asarray(device_angle_deg(scan.angles()))
            distances = encode_distances_mm(scan.ranges, spec.range_max)
            revolutions.append(np.column_stack([angles, distances])[distances > 0])
    return revolutions


def matches(client_scan: list[tuple[float, float]], beams: np.ndarray) -> bool:
    """Every return the client read is a simulated beam: its angle within 1/64 degree."""
    for angle, distance in client_scan:
        gap = np.abs((beams[:, 0] - angle + 180.0) % 360.0 - 180.0)
        near = (gap <= ANGLE_TOL_DEG) & (np.abs(beams[:, 1] - distance) <= DISTANCE_TOL_MM)
        if not near.any():
            return False
    return bool(client_scan)


@pytest.fixture
def emulator() -> Iterator[str]:
    """`fossbot-hil emulate rplidar` on a new pty; yields the port path it printed first."""
    process = subprocess.Popen(
        [sys.executable, "-m", "harness.cli", "emulate", "rplidar", "--scenario", SCENARIO],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        first = process.stdout.readline()  # bounded by pytest-timeout; printed at once
        assert first.startswith("port: /dev/pts/"), first + process.stderr.read()
        yield first.removeprefix("port: ").strip()
    finally:
        process.terminate()
        process.wait(timeout=10)


def first_scans(lidar, count: int = 5) -> list[list[tuple[float, float]]]:
    """The first `count` scans a client yields, as (angle, distance) pairs; then stop."""
    scans = []
    for scan in lidar.iter_scans():
        scans.append([(a, d) for _, a, d in scan])
        if len(scans) == count:
            break
    lidar.stop()
    return scans


def read_with_rplidar_package(port: str) -> tuple[dict, tuple, list[list[tuple[float, float]]]]:
    from rplidar import RPLidar

    lidar = RPLidar(port, timeout=3)
    try:
        return lidar.get_info(), lidar.get_health(), first_scans(lidar)
    finally:
        lidar.disconnect()


def read_with_adafruit(port: str) -> tuple[dict, tuple, list[list[tuple[float, float]]]]:
    from adafruit_rplidar import RPLidar

    lidar = RPLidar(None, port, timeout=3)
    try:
        return lidar.info, lidar.health, first_scans(lidar)
    finally:
        lidar.disconnect()


@pytest.mark.parametrize("reader", [read_with_rplidar_package, read_with_adafruit])
def test_client_reads_info_health_and_the_simulated_scans(emulator: str, reader) -> None:
    """Info and health as an A1M8 answers them; every full scan is a simulated one."""
    tolerate_missing_dtr_on_pty()
    info, health, scans = reader(emulator)
    assert info["model"] == 0x18 and info["firmware"] == (1, 29) and info["hardware"] == 7
    assert health[0] == "Good"
    expected = simulated_revolutions()
    full = scans[1:]  # clients also yield the part-turn before the first start flag
    assert full and all(any(matches(s, e) for e in expected) for s in full), full[0][:5]
