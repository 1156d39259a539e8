"""What a LIDAR is and what it emits (pure data).

- ``spec``: geometry and timing (``LidarSpec``) and the presets of real
  devices (``preset("rplidar_a1")``): add a new LIDAR here;
- ``scan``: the emitted ``Scan``, exactly the fields of sensor_msgs/LaserScan;
- ``mount``: where a device's own zero points on the robot (``LidarMount``).

A LIDAR that also talks over a serial line needs its protocol in
``harness.devices``.
"""

from harness import lazy_exports

_EXPORTS = {
    "LidarSpec": "spec",
    "PRESETS": "spec",
    "preset": "spec",
    "Scan": "scan",
    "LidarMount": "mount",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
