"""The rplidar link: the harness plays the FOSSBot v2's RPLIDAR A1M8 (115200 baud), read
by the board's rplidar-package driver."""

from __future__ import annotations

from harness.devices.profiles import PROFILES
from harness.links.board import serial_lidar

RplidarLink = serial_lidar("rplidar", PROFILES["rplidar"], __name__)
