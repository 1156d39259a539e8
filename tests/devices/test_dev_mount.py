"""The device's mount: where its zero points on the robot, and the board driver's way back.

Scan angles (radians, counter-clockwise, 0 straight ahead) become device
angles (degrees, clockwise from the device's own zero) on a mount; the
bundled board driver's binning (``harness.board_driver.binning``) with the
mount's ``driver_settings()`` must give the scan back at the right angles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.board_driver.binning import ld_ranges, rplidar_ranges
from harness.devices import ldlidar as ld
from harness.devices import rplidar as rp
from harness.devices import rplidar_scans as scans
from harness.devices.profiles import profile
from harness.devices.revolution import Sample, device_angle_deg, samples_at_beams, samples_from_scan
from harness.lidar.mount import FORWARD, LidarMount
from harness.lidar.scan import Scan
from harness.lidar.spec import PRESETS

V2 = LidarMount(yaw_deg=-90.0)  # the FOSSBot v2's A1: zero to the robot's right
MOUNTS = [
    pytest.param(FORWARD, id="forward"),
    pytest.param(V2, id="v2"),
    pytest.param(LidarMount(180.0), id="backward"),
    pytest.param(LidarMount(0.0, mirrored=True), id="upside-down"),
    pytest.param(LidarMount(-90.0, mirrored=True), id="v2-upside-down"),
    pytest.param(LidarMount(37.0), id="37-deg"),
]


def scan_with(preset: str, seed: int = 3) -> Scan:
    """A revolution of the preset: distinct returns on most beams, a few misses and a near wall."""
    spec = PRESETS[preset]
    rng = np.random.default_rng(seed)
    ranges = rng.uniform(0.5, 11.0, spec.samples)
    ranges[rng.random(spec.samples) < 0.1] = np.inf
    ranges[5] = 0.3  # the nearest return, 5 beams left of straight ahead
    return spec.scan(ranges.astype(np.float32))


def expected_bins(scan: Scan, range_min: float, range_max: float, empty: float) -> np.ndarray:
    """The scan as a driver with bins at its beams should publish it."""
    ranges = scan.ranges.astype(np.float64)
    usable = np.isfinite(ranges) & (ranges >= range_min) & (ranges <= range_max)
    return np.where(usable, ranges, empty)


def a1_round_trip(scan: Scan, mount: LidarMount, invert: bool, offset_deg: float) -> np.ndarray:
    """The emulated A1's standard scan on `mount`, decoded and binned as the bundled driver does."""
    device = rp.RplidarDevice()
    device.set_motor(True)
    assert device.receive(rp.encode_request(rp.CMD_SCAN))
    samples = profile("rplidar").revolution(device, scan, 5.5, scan.range_max, mount=mount)
    nodes = scans.decode_standard(device.encode_revolution(samples))
    angles = np.array([s.angle_deg for s in nodes])
    distances = np.array([s.distance_mm for s in nodes])
    return rplidar_ranges(
        angles, distances, 360, range_min=0.15, range_max=12.0, invert=invert,
        angle_offset_deg=offset_deg, mode="nearest",
    )  # fmt: skip


def ld_round_trip(scan: Scan, mount: LidarMount, invert: bool, offset_deg: float) -> np.ndarray:
    """The emulated LD19's packets on `mount`, decoded and binned as the bundled driver does.

    Two turns of the same scan: 450 samples are not whole packets of 12, so
    the first turn's last 6 go out with the second's.
    """
    device = ld.LdlidarDevice(speed_deg_s=3600.0)
    samples = profile("ldlidar").revolution(device, scan, 10.0, 12.0, mount=mount)
    samples = [Sample(s.angle_deg, s.distance_mm, ld.DEFAULT_INTENSITY) for s in samples]
    data = device.encode_revolution(samples, start_ms=0.0)
    data += device.encode_revolution(samples, start_ms=100.0)
    decoded, bad = ld.decode_packets(data)
    assert bad == 0 and len(decoded) == 900
    return ld_ranges(
        np.array([s.angle_deg for s in decoded]),
        np.array([s.distance_mm for s in decoded]),
        np.array([s.quality for s in decoded]),
        450,
        invert=invert,
        angle_offset_deg=offset_deg,
    )


def test_v2_mount_puts_straight_ahead_at_device_270_and_the_left_at_180() -> None:
    """Zero to the right, clockwise: ahead is 270, left 180, behind 90, right 0."""
    for ccw, device in ((0.0, 270.0), (math.pi / 2, 180.0), (math.pi, 90.0), (-math.pi / 2, 0.0)):
        assert device_angle_deg(ccw, V2) == pytest.approx(device)
    ranges = np.full(360, np.inf)
    ranges[0] = 1.0  # straight ahead
    ranges[90] = 2.0  # the robot's left
    scan = PRESETS["rplidar_a1"].scan(ranges.astype(np.float32))
    hits = [s for s in samples_from_scan(scan, mount=V2) if s.distance_mm > 0]
    assert hits == [Sample(180.0, 2000.0, 47), Sample(270.0, 1000.0, 47)]
    hits = [s for s in samples_at_beams(scan, mount=V2) if s.distance_mm > 0]
    assert [(s.angle_deg, s.distance_mm) for s in hits] == [(180.0, 2000.0), (270.0, 1000.0)]


def test_a_mirrored_device_counts_counter_clockwise_from_its_zero() -> None:
    """Upside down, a clockwise device counts counter-clockwise seen from above."""
    upside_down = LidarMount(0.0, mirrored=True)
    assert device_angle_deg(math.pi / 2, upside_down) == pytest.approx(90.0)
    assert device_angle_deg(-math.pi / 2, upside_down) == pytest.approx(270.0)
    v2_upside_down = LidarMount(-90.0, mirrored=True)
    assert device_angle_deg(0.0, v2_upside_down) == pytest.approx(90.0)
    assert device_angle_deg(-math.pi / 2, v2_upside_down) == pytest.approx(0.0)


def slow_device_angle_deg(mount: LidarMount, scan_deg: float) -> float:
    """The mount's definition, one beam at a time: clockwise from its zero (counter-
    clockwise when mirrored), in [0, 360)."""
    turn = scan_deg - mount.yaw_deg if mount.mirrored else mount.yaw_deg - scan_deg
    return turn % 360.0


@pytest.mark.parametrize("mount", MOUNTS)
def test_every_beam_is_where_the_mount_says(mount: LidarMount) -> None:
    """The vectorised angles equal the mount's definition, beam by beam (slow reference)."""
    for spec in PRESETS.values():
        scan = spec.scan(np.ones(spec.samples, dtype=np.float32))
        fast = np.asarray(device_angle_deg(scan.angles(), mount))
        slow = [slow_device_angle_deg(mount, math.degrees(a)) for a in scan.angles().tolist()]
        gap = np.abs((fast - np.array(slow) + 180.0) % 360.0 - 180.0)
        assert gap.max() < 1e-9 and np.all((fast >= 0.0) & (fast < 360.0))


@pytest.mark.parametrize("mount", MOUNTS)
def test_samples_come_in_increasing_device_angle_on_any_mount(mount: LidarMount) -> None:
    """Whatever the mount, a revolution starts near device 0 and runs up to 360."""
    for spec in PRESETS.values():
        scan = spec.scan(np.linspace(0.5, 5.0, spec.samples).astype(np.float32))
        for samples in (
            samples_from_scan(scan, mount=mount),
            samples_from_scan(scan, samples_per_rev=450, mount=mount),
            samples_at_beams(scan, max_count=197, mount=mount),
        ):
            angles = [s.angle_deg for s in samples]
            assert angles == sorted(angles) and 0.0 <= angles[0] < 360.0 / len(angles) + 1.0
            assert angles[-1] < 360.0


@pytest.mark.parametrize("mount", MOUNTS)
def test_resampling_takes_the_beam_the_mount_points_at(mount: LidarMount) -> None:
    """Device angle j looks at the scan angle the mount turns it into (1-degree beams)."""
    ranges = np.arange(1, 361, dtype=np.float32)  # beam i (CCW i degrees) reads i + 1 m
    scan = PRESETS["rplidar_a1"].scan(ranges)
    for sample in samples_from_scan(scan, samples_per_rev=360, mount=mount):
        j = sample.angle_deg
        scan_deg = mount.yaw_deg + j if mount.mirrored else mount.yaw_deg - j
        assert sample.distance_mm == pytest.approx(1000.0 * (round(scan_deg) % 360 + 1))


@pytest.mark.parametrize("mount", MOUNTS)
def test_the_a1_round_trip_through_the_bundled_driver_gives_the_scan_back(
    mount: LidarMount,
) -> None:
    """Emulated on `mount`, read with its driver_settings: every bin as the scan had it."""
    scan = scan_with("rplidar_a1")
    invert, offset = mount.driver_settings()
    got = a1_round_trip(scan, mount, invert, offset)
    expected = expected_bins(scan, 0.15, 12.0, math.inf)
    np.testing.assert_allclose(got, expected, atol=3e-4)  # the A1's 1/4 mm, the agent's 0.1 mm
    assert int(np.argmin(got)) == 5  # the nearest return, 5 degrees left


@pytest.mark.parametrize("mount", MOUNTS)
def test_a_wrong_offset_turns_the_scan_by_the_difference(mount: LidarMount) -> None:
    """The driver's offset 30 deg more than the mount's yaw: the whole scan 30 bins CCW."""
    scan = scan_with("rplidar_a1")
    invert, offset = mount.driver_settings()
    got = a1_round_trip(scan, mount, invert, offset + 30.0)
    expected = expected_bins(scan, 0.15, 12.0, math.inf)
    np.testing.assert_allclose(got, np.roll(expected, 30), atol=3e-4)


def test_the_v2_device_read_with_a_generic_driver_is_turned_by_90_degrees() -> None:
    """v2 mount, driver at (invert, 0): the wall ahead comes back on the left (+90 deg)."""
    scan = scan_with("rplidar_a1")
    got = a1_round_trip(scan, V2, True, 0.0)
    np.testing.assert_allclose(got, np.roll(expected_bins(scan, 0.15, 12.0, math.inf), 90), 0, 3e-4)
    assert int(np.argmin(got)) == 95


def test_a_mirrored_device_read_without_the_flip_comes_back_mirrored() -> None:
    """Upside down but read with invert true: bin k holds what was at -k."""
    scan = scan_with("rplidar_a1")
    got = a1_round_trip(scan, LidarMount(0.0, mirrored=True), True, 0.0)
    expected = expected_bins(scan, 0.15, 12.0, math.inf)
    np.testing.assert_allclose(got, expected[(-np.arange(360)) % 360], atol=3e-4)


@pytest.mark.parametrize("mount", MOUNTS)
def test_the_ld19_round_trip_gives_the_scan_back(mount: LidarMount) -> None:
    """450 samples a turn, read with the mount's driver_settings: every bin as the scan had it."""
    scan = scan_with("ld19")
    invert, offset = mount.driver_settings()
    got = ld_round_trip(scan, mount, invert, offset)
    raw = scan.ranges.astype(np.float64)
    expected = np.where(np.isfinite(raw) & (raw <= 12.0), raw, math.nan)
    np.testing.assert_allclose(got, expected, atol=1e-3)
    assert int(np.nanargmin(got)) == 5


def test_resampled_devices_look_where_the_generic_mount_looks() -> None:
    """The v2's -90 deg is 112.5 LD19 steps: its samples start half a step past its zero,
    so they look straight ahead, as on the generic mount, not half-way between beams."""
    scan = scan_with("ld19")
    forward = samples_from_scan(scan, samples_per_rev=450, mount=FORWARD)
    assert forward[1].angle_deg == 0.8  # the generic mount: unchanged, from 0
    v2 = samples_from_scan(scan, samples_per_rev=450, mount=V2)
    assert v2[0].angle_deg == pytest.approx(0.4) and v2[-1].angle_deg < 360.0
    assert [s.distance_mm for s in v2] == [
        forward[round((90.0 + s.angle_deg) / 0.8) % 450].distance_mm for s in v2
    ]
