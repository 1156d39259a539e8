"""`fossbot-hil emulate` read by independent RPLIDAR clients over a real pty.

The `rplidar` package, Adafruit's client and rplidar-roboticia (what the
FOSSBot v2 runs) must get device info, health and scans whose angles and
distances match the simulated beams within the A1's quantisation (1/64
degree, 1/4 mm): in standard mode each sample is reported at the angle its
beam was cast. Each client runs unmodified in its own process, in a shell
given the "modem lines" line emulate printed, so its DTR calls work on the
pty and reach the emulator.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from emulator_process import Emulator
from third_party import roboticia_site

from harness.devices.revolution import device_angle_deg, encode_distances_mm
from harness.runner.settings import RunSettings, fault_profile
from harness.scenario.files import resolve_scenario
from harness.scenario.mount import scenario_mount
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
            angles = np.asarray(device_angle_deg(scan.angles(), scenario_mount(scenario)))
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
def emulator() -> Iterator[Emulator]:
    """`fossbot-hil emulate rplidar -v` on a new pty, as a user starts it."""
    process = Emulator("rplidar", "--scenario", SCENARIO, "-v")
    try:
        yield process
    finally:
        process.close()


def as_pairs(scans: list[list[list[float]]]) -> list[list[tuple[float, float]]]:
    return [[(angle, distance) for angle, distance in scan] for scan in scans]


@pytest.mark.parametrize("library", ["rplidar", "adafruit"])
def test_client_reads_info_health_and_the_simulated_scans(emulator: Emulator, library) -> None:
    """Info and health as an A1M8 answers them; every full scan is a simulated one."""
    read = emulator.run_client(library, "--ask", "info,health", "--scans", "5")
    info, health, scans = read["info"], read["health"], as_pairs(read["scans"])
    assert info["model"] == 0x18 and tuple(info["firmware"]) == (1, 29) and info["hardware"] == 7
    assert health[0] == "Good"
    expected = simulated_revolutions()
    full = scans[1:]  # clients also yield the part-turn before the first start flag
    assert full and all(any(matches(s, e) for e in expected) for s in full), full[0][:5]


@pytest.mark.slow  # the agent's own waits (4.7 s with the library's), the emulator's start
def test_the_fossbot_v2_agents_client_gets_scans_and_drives_the_motor(emulator) -> None:
    """rplidar-roboticia 0.9.5 (the real robot's) makes the agent's calls, unmodified:
    the emulator follows its DTR (motor off from its open, on when it scans) and the
    client gets simulated scans."""
    site = str(roboticia_site())  # first on the path: its rplidar, not the venv's 0.9.2
    read = emulator.run_client(
        "rplidar", "--scans", "3", "--fossbot-agent", env={"PYTHONPATH": site}
    )
    assert read["info"]["model"] == 0x18
    expected = simulated_revolutions()
    full = as_pairs(read["scans"])[1:]
    assert full and all(any(matches(s, e) for e in expected) for s in full), full[0][:5]
    emulator.wait_for(r"the client closed", 10)
    log = emulator.text()
    off = log.index("board's DTR asserted: motor off")
    reset = log.index("request RESET")
    on = log.index("board's DTR deasserted: motor on", reset)
    assert off < reset < on < log.index("request SCAN"), log
