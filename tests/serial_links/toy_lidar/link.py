"""The toy LIDAR's link, as a link module in harness/links/ would be: its name and its
device profile, nothing else (the board link does the rest)."""

from __future__ import annotations

from harness.links.board import serial_lidar
from toy_lidar import NAME
from toy_lidar.preset import PROFILE

ToyLink = serial_lidar(NAME, PROFILE, __name__)
