"""Each emulated LIDAR model: its device, line rate and the board driver that reads it.

Shared by the serial links and by `fossbot-hil emulate`; imports no rclpy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from harness.devices.protocol import LineDevice
from harness.devices.revolution import Sample, samples_at_beams, samples_from_scan
from harness.errors import ConfigError
from harness.lidar.mount import FORWARD, LidarMount
from harness.lidar.scan import Scan

# A revolution of standard nodes may fill this share of the line's time per
# revolution; more beams than that are thinned (the A1's express mode and
# its replies need room too).
LINE_SHARE = 0.9


@dataclass(frozen=True)
class DeviceProfile:
    """What differs between LIDAR models on a serial line."""

    name: str
    description: str
    baudrate: int
    driver_module: str  # the bundled board driver, run as `python -m`
    make_device: Callable[[float], LineDevice]  # (revolutions per second) -> device
    samples_per_rev: Callable[[Any, float], int]  # (device, rate_hz) -> native samples
    streams_unasked: bool  # LD19: always streaming; RPLIDAR: only after a SCAN request
    at_beam_angles: Callable[[Any], bool] = lambda device: False  # (device) -> no resampling?

    def revolution(
        self,
        device: Any,
        scan: Scan,
        rate_hz: float,
        max_range_m: float | None,
        *,
        mount: LidarMount = FORWARD,
    ) -> list[Sample]:
        """The samples `device` sends for one revolution of `scan` at `rate_hz`, on `mount`.

        A device that reports each sample's angle (the A1's standard nodes) sends
        every beam at its own angle, as many as the line carries (else its native
        count); otherwise the revolution is resampled to the native count.
        """
        native = self.samples_per_rev(device, rate_hz)
        if self.at_beam_angles(device):
            bytes_per_rev = LINE_SHARE * self.baudrate / 10 / rate_hz
            fits = scan.ranges.size * device.bytes_per_sample <= bytes_per_rev
            count = None if fits else native
            return samples_at_beams(scan, max_count=count, max_range_m=max_range_m, mount=mount)
        return samples_from_scan(scan, samples_per_rev=native, max_range_m=max_range_m, mount=mount)


def _rplidar(rate_hz: float) -> LineDevice:
    from harness.devices.rplidar import RplidarDevice

    return RplidarDevice()


def _ldlidar(rate_hz: float) -> LineDevice:
    from harness.devices.ldlidar import LdlidarDevice

    return LdlidarDevice(speed_deg_s=360.0 * rate_hz)


PROFILES: dict[str, DeviceProfile] = {
    profile.name: profile
    for profile in (
        DeviceProfile(
            name="rplidar",
            description="Slamtec RPLIDAR A1M8 (the FOSSBot v2's LIDAR), 115200 baud",
            baudrate=115200,
            driver_module="harness.board_driver.rplidar_node",
            make_device=_rplidar,
            samples_per_rev=lambda device, rate_hz: device.samples_per_revolution(rate_hz),
            streams_unasked=False,
            at_beam_angles=lambda device: device.mode != "express",  # standard nodes (or idle)
        ),
        DeviceProfile(
            name="ldlidar",
            description="LDROBOT LD06/LD19, 230400 baud, stream only",
            baudrate=230400,
            driver_module="harness.board_driver.ldlidar_node",
            make_device=_ldlidar,
            samples_per_rev=lambda device, rate_hz: device.samples_per_revolution,
            streams_unasked=True,
        ),
    )
}


def add_profile(device: DeviceProfile) -> DeviceProfile:
    """Make a LIDAR model from outside the harness known by its name (once); returns it."""
    known = PROFILES.get(device.name)
    if known is not None and known != device:
        raise RuntimeError(f"LIDAR device {device.name!r} is defined twice")
    PROFILES[device.name] = device
    return device


def profile(name: str) -> DeviceProfile:
    """The named LIDAR model, or a ConfigError listing the known ones."""
    try:
        return PROFILES[name]
    except KeyError:
        known = ", ".join(PROFILES)
        raise ConfigError(f"unknown LIDAR device {name!r} (known: {known})") from None
