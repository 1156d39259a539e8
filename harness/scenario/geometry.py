"""How the world represents scenario shapes, as pure numbers (no pybullet).

Scenario validation needs to know what a shape will cost the simulator
before the world exists (a thousand fine cylinder meshes take gigabytes),
so the counts live here and ``harness.sim.world`` builds from them.
"""

from __future__ import annotations

import math

__all__ = ["CYLINDER_SAGITTA", "CYLINDER_SEGMENTS", "cylinder_segments"]

# Scenario cylinders become triangle-mesh prisms: Bullet's ray test against
# an implicit cylinder is off by up to ~1 mm, a fine prism by far less.
CYLINDER_SAGITTA = 2e-5  # m, largest gap between the prism and the true circle
CYLINDER_SEGMENTS = (64, 2048)  # fewest and most sides of one prism


def cylinder_segments(radius: float) -> int:
    """Sides of the prism standing in for a cylinder of `radius` (m)."""
    step = math.acos(max(-1.0, 1.0 - CYLINDER_SAGITTA / radius))
    lo, hi = CYLINDER_SEGMENTS
    return min(hi, max(lo, math.ceil(math.pi / step)))
