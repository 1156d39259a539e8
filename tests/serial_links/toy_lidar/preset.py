"""The toy LIDAR's presets: its beam layout (for scenarios) and its device profile."""

from __future__ import annotations

import math

from harness.devices.profiles import DeviceProfile, add_profile
from harness.lidar.spec import LidarSpec, add_preset
from toy_lidar.codec import BAUD, SAMPLES_PER_REV, ToyDevice

SPEC = add_preset(
    LidarSpec(
        name="toy_lidar",
        samples=SAMPLES_PER_REV,
        angle_min=0.0,
        angle_increment=2 * math.pi / SAMPLES_PER_REV,
        range_min=0.05,
        range_max=8.0,
        rate_hz=10.0,
    )
)

PROFILE = add_profile(
    DeviceProfile(
        name="toylidar",
        description="a LIDAR of the tests: one ASCII line a revolution, 460800 baud",
        baudrate=BAUD,
        driver_module="toy_lidar.driver",
        make_device=lambda rate_hz: ToyDevice(),
        samples_per_rev=lambda device, rate_hz: SAMPLES_PER_REV,
        streams_unasked=True,
        at_beam_angles=lambda device: True,
    )
)
