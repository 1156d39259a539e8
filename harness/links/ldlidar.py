"""The ldlidar link: the harness plays an LDROBOT LD06/LD19 (230400 baud, stream only),
read by the board's LD driver."""

from __future__ import annotations

from harness.devices.profiles import PROFILES
from harness.links.board import serial_lidar

LdlidarLink = serial_lidar("ldlidar", PROFILES["ldlidar"], __name__)
