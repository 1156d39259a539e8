"""The truth: a PyBullet world, its LIDAR's ray casts and the scripted robot motion.

Names load on first use, so the pure ``motion`` loads without pybullet.
Add a kind of obstacle in ``world``, a kind of motion in ``motion``.
"""

from harness import lazy_exports

_EXPORTS = {
    "Simulation": "simulation",
    "SimTick": "simulation",
    "World": "world",
    "LidarModel": "lidar",
    "MotionScript": "motion",
    "Pose": "motion",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
