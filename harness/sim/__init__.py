"""The simulator: a PyBullet world, its LIDAR and the scripted robot motion.

``Simulation`` is what the runner uses. Names are imported lazily so the
pure motion helpers (``harness.sim.motion``) load without pybullet.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # for type checkers and IDEs; at run time names load on first use
    from harness.sim.lidar import LidarModel
    from harness.sim.motion import MotionScript, Pose
    from harness.sim.simulation import SimTick, Simulation
    from harness.sim.world import World

_EXPORTS = {
    "Simulation": "harness.sim.simulation",
    "SimTick": "harness.sim.simulation",
    "World": "harness.sim.world",
    "LidarModel": "harness.sim.lidar",
    "MotionScript": "harness.sim.motion",
    "Pose": "harness.sim.motion",
}

__all__ = ["LidarModel", "MotionScript", "Pose", "SimTick", "Simulation", "World"]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'harness.sim' has no attribute {name!r}")
