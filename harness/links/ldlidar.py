"""The ldlidar link: the harness plays an LDROBOT LD06/LD19 (230400 baud, stream only)."""

from __future__ import annotations

from harness.devices.profiles import PROFILES
from harness.links.base import register
from harness.links.board import BoardLink


@register("ldlidar")
class LdlidarLink(BoardLink):
    """An emulated LD19 read by the board's LD driver."""

    profile = PROFILES["ldlidar"]
