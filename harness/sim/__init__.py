"""The truth: a PyBullet world, its LIDAR's ray casts and the scripted robot motion.

``Simulation`` is what the runner uses: one scenario's world, stepped in
lockstep, yielding each revolution's true ranges. Names load on first use,
so the pure motion helpers (``harness.sim.motion``) load without pybullet.
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
