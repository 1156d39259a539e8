"""A1 standard mode: each sample at the angle the simulator cast its beam (within 1/64 deg).

Resampling 360 beams into the A1's 358 samples a revolution shifted
readings by up to half a degree; standard nodes carry each sample's own
angle, so the device reports the beams where they looked instead.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.devices import rplidar as rp
from harness.devices import rplidar_scans as scans
from harness.devices.profiles import profile
from harness.devices.revolution import device_angle_deg, samples_at_beams
from harness.lidar.scan import Scan
from harness.lidar.spec import PRESETS

Q6_DEG = 1 / 64


def scan_from(preset: str, seed: int = 7) -> Scan:
    """A revolution of the preset with a return on every beam (distinct distances)."""
    spec = PRESETS[preset]
    ranges = np.random.default_rng(seed).uniform(0.2, 11.0, spec.samples).astype(np.float32)
    return spec.scan(ranges)


def decoded_standard(scan: Scan, rate_hz: float) -> list[tuple[float, float]]:
    """What a host decodes from the emulated A1's SCAN stream of this revolution."""
    device = rp.RplidarDevice()
    device.set_motor(True)
    assert device.receive(rp.encode_request(rp.CMD_SCAN))
    samples = profile("rplidar").revolution(device, scan, rate_hz, scan.range_max)
    nodes = scans.decode_standard(device.encode_revolution(samples))
    return [(s.angle_deg, s.distance_mm) for s in nodes]


def beam_angle_gap(angle: float, beams: np.ndarray) -> np.ndarray:
    return np.abs((beams - angle + 180.0) % 360.0 - 180.0)


def test_a1_at_5_5_hz_reports_every_beam_at_its_own_angle() -> None:
    """360 beams at 5.5 Hz fit the line: 360 nodes, each within 1/64 deg of its beam."""
    scan = scan_from("rplidar_a1")
    decoded = decoded_standard(scan, 5.5)
    assert len(decoded) == 360
    beams = np.asarray(device_angle_deg(scan.angles()))
    mm = scan.ranges.astype(np.float64) * 1000.0
    for angle, distance in decoded:
        i = int(np.argmin(beam_angle_gap(angle, beams)))
        assert beam_angle_gap(angle, beams)[i] <= Q6_DEG / 2 + 1e-9
        assert abs(distance - mm[i]) <= 0.125 + 1e-6


def test_more_beams_than_the_line_carries_keeps_beams_at_their_angles() -> None:
    """Gazebo's 360 beams at 10 Hz exceed 115200 baud: the native 197, still at beam angles."""
    scan = scan_from("gazebo")
    decoded = decoded_standard(scan, 10.0)
    assert len(decoded) == rp.RplidarDevice().samples_per_revolution(10.0) == 197
    beams = np.asarray(device_angle_deg(scan.angles()))
    assert max(beam_angle_gap(a, beams).min() for a, _ in decoded) <= Q6_DEG / 2 + 1e-9


def test_express_mode_still_resamples_to_its_capsules() -> None:
    """Express capsules carry evenly spaced angles: that mode keeps the native resampling."""
    device = rp.RplidarDevice()
    device.receive(rp.encode_request(rp.CMD_EXPRESS_SCAN, bytes(5)))
    samples = profile("rplidar").revolution(device, scan_from("rplidar_a1"), 5.5, 12.0)
    assert len(samples) == device.samples_per_revolution(5.5) == 716
    steps = np.diff([s.angle_deg for s in samples])
    assert np.allclose(steps, 360.0 / 716)


def test_samples_at_beams_thins_evenly_and_rejects_nonsense() -> None:
    scan = scan_from("rplidar_a1")
    kept = samples_at_beams(scan, max_count=90)
    assert len(kept) == 90
    assert np.allclose(np.diff(sorted(s.angle_deg for s in kept)), 4.0)
    assert len(samples_at_beams(scan, max_count=1000)) == 360
    with pytest.raises(ValueError, match="max_count must be positive"):
        samples_at_beams(scan, max_count=0)
    assert math.isclose(samples_at_beams(scan)[1].angle_deg, 1.0)
