"""Both emulated LIDARs satisfy the declared device interface the server drives."""

from __future__ import annotations

import pytest

from harness.devices.ldlidar import LdlidarDevice
from harness.devices.profiles import PROFILES
from harness.devices.protocol import DeviceDefaults, LineDevice
from harness.devices.rplidar import RplidarDevice


@pytest.mark.parametrize("device", [RplidarDevice(), LdlidarDevice()], ids=["rplidar", "ldlidar"])
def test_each_device_is_a_line_device(device: LineDevice) -> None:
    assert isinstance(device, LineDevice)
    assert isinstance(device.mode, str) and isinstance(device.session, int)
    assert device.samples_per_packet >= 1
    assert isinstance(dict(device.counters), dict)


@pytest.mark.parametrize("name", sorted(PROFILES))
def test_every_profile_makes_a_line_device(name: str) -> None:
    assert isinstance(PROFILES[name].make_device(10.0), LineDevice)


def test_the_capabilities_each_device_declares() -> None:
    a1, ld06 = RplidarDevice(), LdlidarDevice()
    assert a1.follows_motor_line and not a1.packetized
    assert ld06.packetized and not ld06.follows_motor_line
    assert ld06.mode == "streaming" and ld06.finish_reset() == b"" and not ld06.rebooting
    ld06.set_rate(5.0)
    assert ld06.speed_deg_s == 1800.0


def test_a_device_without_its_own_stream_is_not_one() -> None:
    """The defaults declare what a device may lack; its mode and encoder it must have."""
    assert not isinstance(DeviceDefaults(), LineDevice)
