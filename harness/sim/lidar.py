"""The simulated LIDAR: true ranges by ray casting from the LIDAR link.

One ``rayTestBatch`` per revolution, the beam directions fixed in the LIDAR
frame and only rotated into the world each scan. The result is the ground
truth; what a driver publishes of it is the fault stage's job. The whole
revolution is cast from one pose: the robot moves a few centimetres per
turn, which the lab's nodes cannot tell from a snapshot.
"""

from __future__ import annotations

import math

import numpy as np

from harness.lidar.spec import LidarSpec
from harness.sim.bullet import pb
from harness.sim.world import RAY_MASK, World, link_frame_pose

MAX_RAYS_PER_BATCH = 16383  # rayTestBatch silently returns nothing above this


def beam_angles(spec: LidarSpec) -> np.ndarray:
    """Angle of each beam in the LIDAR frame: angle_min + i * angle_increment."""
    return spec.angle_min + np.arange(spec.samples, dtype=np.float64) * spec.angle_increment


def beam_directions(spec: LidarSpec) -> np.ndarray:
    """Unit beam directions in the LIDAR frame (REP-103: CCW from +x, in the xy plane)."""
    angles = beam_angles(spec)
    return np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)


class LidarModel:
    """Casts the beams of `spec` from one link of one body in one PyBullet client."""

    def __init__(
        self, client: int, body: int, link_index: int, spec: LidarSpec, *, ray_mask: int = -1
    ) -> None:
        self.client, self.body, self.link_index, self.spec = client, body, link_index, spec
        self.ray_mask = ray_mask  # collisionFilterMask: which collision groups the beams see
        self._directions = beam_directions(spec)

    @classmethod
    def for_world(cls, world: World, spec: LidarSpec) -> LidarModel:
        """The LIDAR on the world's robot, blind to the robot itself and to the floor."""
        return cls(world.client, world.robot, world.lidar_link, spec, ray_mask=RAY_MASK)

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        """World origin (3,) and rotation matrix (3, 3) of the LIDAR frame now."""
        position, orientation = link_frame_pose(self.client, self.body, self.link_index)
        rotation = np.array(pb.getMatrixFromQuaternion(orientation), dtype=np.float64)
        return np.asarray(position, dtype=np.float64), rotation.reshape(3, 3)

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Start and end points (n, 3) of every beam, in world coordinates."""
        origin, rotation = self.pose()
        ends = origin + (self._directions @ rotation.T) * self.spec.range_max
        starts = np.empty_like(ends)
        starts[...] = origin  # a filled array: half the time of a broadcast made contiguous
        return starts, ends

    def cast(self, starts: np.ndarray, ends: np.ndarray) -> list[tuple]:
        """Each beam's ``rayTestBatch`` hit, cast in batches under its cap."""
        hits: list[tuple] = []
        for lo in range(0, len(ends), MAX_RAYS_PER_BATCH):
            hits += pb.rayTestBatch(
                starts[lo : lo + MAX_RAYS_PER_BATCH],
                ends[lo : lo + MAX_RAYS_PER_BATCH],
                numThreads=1,
                collisionFilterMask=self.ray_mask,
                physicsClientId=self.client,
            )
        return hits

    def truth(self) -> np.ndarray:
        """True range of each beam (float64, m); inf where nothing is within range_max."""
        inf = math.inf  # a local: `np.inf` per beam was a third of this loop's time
        fractions = np.array([h[2] if h[0] >= 0 else inf for h in self.cast(*self.rays())])
        return fractions * self.spec.range_max

    def truth_reference(self) -> np.ndarray:
        """The same as truth(), one ``rayTest`` per beam: slow and obviously right."""
        origin, rotation = self.pose()
        out = np.full(self.spec.samples, np.inf)
        for i, direction in enumerate(self._directions):
            end = origin + rotation @ direction * self.spec.range_max
            hit = pb.rayTest(
                origin.tolist(),
                end.tolist(),
                collisionFilterMask=self.ray_mask,
                physicsClientId=self.client,
            )[0]
            if hit[0] >= 0:
                out[i] = hit[2] * self.spec.range_max
        return out
