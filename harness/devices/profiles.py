"""Each emulated LIDAR model: its device, line rate and the board driver that reads it.

Shared by the serial links and by `fossbot-hil emulate`; imports no rclpy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from harness.errors import ConfigError


@dataclass(frozen=True)
class DeviceProfile:
    """What differs between LIDAR models on a serial line."""

    name: str
    description: str
    baudrate: int
    driver_module: str  # the bundled board driver, run as `python -m`
    make_device: Callable[[float], Any]  # (revolutions per second) -> device
    samples_per_rev: Callable[[Any, float], int]  # (device, rate_hz) -> native samples
    streams_unasked: bool  # LD19: always streaming; RPLIDAR: only after a SCAN request


def _rplidar(rate_hz: float) -> Any:
    from harness.devices.rplidar import RplidarDevice

    return RplidarDevice()


def _ldlidar(rate_hz: float) -> Any:
    from harness.devices.ldlidar import LdlidarDevice

    return LdlidarDevice(speed_deg_s=360.0 * rate_hz)


PROFILES: dict[str, DeviceProfile] = {
    "rplidar": DeviceProfile(
        name="rplidar",
        description="Slamtec RPLIDAR A1M8 (the FOSSBot v2's LIDAR), 115200 baud",
        baudrate=115200,
        driver_module="harness.board_driver.rplidar_node",
        make_device=_rplidar,
        samples_per_rev=lambda device, rate_hz: device.samples_per_revolution(rate_hz),
        streams_unasked=False,
    ),
    "ldlidar": DeviceProfile(
        name="ldlidar",
        description="LDROBOT LD06/LD19, 230400 baud, stream only",
        baudrate=230400,
        driver_module="harness.board_driver.ldlidar_node",
        make_device=_ldlidar,
        samples_per_rev=lambda device, rate_hz: device.samples_per_revolution,
        streams_unasked=True,
    ),
}


def profile(name: str) -> DeviceProfile:
    try:
        return PROFILES[name]
    except KeyError:
        known = ", ".join(PROFILES)
        raise ConfigError(f"unknown LIDAR device {name!r} (known: {known})") from None
