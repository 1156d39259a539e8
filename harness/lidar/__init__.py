"""What a LIDAR is and what it emits (pure data).

``spec`` (``LidarSpec`` and the real devices' presets: add a new LIDAR
here), ``scan`` (the emitted ``Scan``), ``mount`` (where a device's zero
points). A serial LIDAR also needs its protocol in ``harness.devices``.
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
