"""The rplidar link: the harness plays the FOSSBot v2's RPLIDAR A1M8 (115200 baud)."""

from __future__ import annotations

from harness.devices.profiles import PROFILES
from harness.links.base import register
from harness.links.board import BoardLink


@register("rplidar")
class RplidarLink(BoardLink):
    """An emulated A1M8 read by the board's rplidar-package driver."""

    profile = PROFILES["rplidar"]
