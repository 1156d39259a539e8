"""The PyBullet world of one scenario: floor, obstacles and the robot.

Each ``World`` owns its physics client, so several live in one process (two
runs compared for determinism); a fixed 240 Hz step and a fixed build order
make it deterministic. The robot and the floor sit in collision groups the
LIDAR's ray mask leaves out, so it never sees its own robot (whatever the
URDF's collision geometry) nor the floor when the robot pitches.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from harness.errors import ConfigError, OptionError
from harness.safe_text import shown
from harness.scenario.geometry import cylinder_segments
from harness.scenario.model_files import check_model_file, find_model_file, robot_models_dir
from harness.scenario.schema import Box, Cylinder, Model, Scenario, Wall
from harness.sim import bullet
from harness.sim.bullet import pb
from harness.sim.motion import WheelGeometry

TIME_STEP = 1.0 / 240.0  # s; the only physics step the harness uses
GRAVITY = 9.81  # m/s^2
FLOOR_FRICTION = 1.0

ROBOT_GROUP = 1 << 6  # collision filter group of every robot link
FLOOR_GROUP = 1 << 7  # collision filter group of the floor
_STATIC_GROUP = 2  # Bullet's StaticFilter
RAY_MASK = -1 & ~(ROBOT_GROUP | FLOOR_GROUP)  # what the LIDAR may hit

_OBSTACLE_RGBA = (0.8, 0.55, 0.3, 1.0)
_FLOOR_RGBA = (0.85, 0.85, 0.85, 1.0)


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion (x, y, z, w) of a rotation by `yaw` about +z."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def quaternion_yaw(q: Sequence[float]) -> float:
    """Heading (rotation about +z) of a quaternion (x, y, z, w)."""
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class World:
    """A PyBullet world built from a scenario; close it (or use ``with``)."""

    def __init__(self, scenario: Scenario, *, gui: bool = False) -> None:
        self.scenario = scenario
        self.where = shown(scenario.source or "<scenario>")
        if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
            raise OptionError("gui", "{gui} needs a display")
        self.gui = gui
        self.client: int = bullet.connect(gui)
        if self.client < 0:
            raise ConfigError("cannot start PyBullet" + (" with a GUI" if gui else ""))
        try:
            self._build()
        except BaseException:
            self.close()
            raise

    # -- building ---------------------------------------------------------

    def _build(self) -> None:
        c = self.client
        pb.setPhysicsEngineParameter(
            fixedTimeStep=TIME_STEP,
            numSubSteps=0,
            deterministicOverlappingPairs=1,
            physicsClientId=c,
        )
        pb.setGravity(0.0, 0.0, -GRAVITY, physicsClientId=c)
        self.floor = self._add_floor()
        self.obstacle_bodies: list[tuple[int, ...]] = [
            self._add_obstacle(i, obstacle) for i, obstacle in enumerate(self.scenario.obstacles)
        ]
        self.robot_path = self.resolve(self.scenario.robot.urdf, "robot.urdf")
        self.robot = self._load_robot()
        self.lidar_link = self.link_index(self.scenario.robot.lidar_link, "robot.lidar_link")

    def _add_floor(self) -> int:
        c = self.client
        shape = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=c)
        visual = pb.createVisualShape(
            pb.GEOM_BOX,
            halfExtents=(20.0, 20.0, 0.001),
            visualFramePosition=(0.0, 0.0, -0.001),
            rgbaColor=_FLOOR_RGBA,
            physicsClientId=c,
        )
        floor = pb.createMultiBody(0.0, shape, visual, physicsClientId=c)
        pb.changeDynamics(floor, -1, lateralFriction=FLOOR_FRICTION, physicsClientId=c)
        pb.setCollisionFilterGroupMask(
            floor, -1, FLOOR_GROUP, -1 & ~_STATIC_GROUP, physicsClientId=c
        )
        return floor

    def _add_obstacle(self, index: int, obstacle: Wall | Box | Cylinder | Model) -> tuple[int, ...]:
        if isinstance(obstacle, Wall):
            (x0, y0), (x1, y1) = obstacle.start, obstacle.end
            half = (math.dist(obstacle.start, obstacle.end) / 2.0, obstacle.thickness / 2.0)
            centre, yaw = ((x0 + x1) / 2.0, (y0 + y1) / 2.0), math.atan2(y1 - y0, x1 - x0)
            return (self._add_box(centre, (*half, obstacle.height / 2.0), yaw),)
        if isinstance(obstacle, Box):
            extents = tuple(s / 2.0 for s in obstacle.size)
            return (self._add_box(obstacle.position, extents, obstacle.yaw),)
        if isinstance(obstacle, Cylinder):
            return (self._add_cylinder(obstacle),)
        return self._add_model(index, obstacle)

    def _add_box(self, xy: tuple[float, float], half: tuple[float, ...], yaw: float) -> int:
        c = self.client
        shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=c)
        visual = pb.createVisualShape(
            pb.GEOM_BOX, halfExtents=half, rgbaColor=_OBSTACLE_RGBA, physicsClientId=c
        )
        return self._static_body(shape, visual, (xy[0], xy[1], half[2]), yaw_quaternion(yaw))

    def _add_cylinder(self, cyl: Cylinder) -> int:
        c = self.client
        vertices, indices = cylinder_prism(cyl.radius, cyl.height)
        mesh = {"vertices": vertices, "indices": indices, "flags": pb.GEOM_FORCE_CONCAVE_TRIMESH}
        shape = pb.createCollisionShape(pb.GEOM_MESH, **mesh, physicsClientId=c)
        look = {"radius": cyl.radius, "length": cyl.height, "rgbaColor": _OBSTACLE_RGBA}
        visual = pb.createVisualShape(pb.GEOM_CYLINDER, **look, physicsClientId=c)
        return self._static_body(shape, visual, (*cyl.position[:2], cyl.height / 2.0))

    def _static_body(
        self, shape: int, visual: int, position: Sequence[float], orientation: Sequence[float] = ()
    ) -> int:
        """A body of mass 0 (it never moves) at `position` (turned by `orientation`)."""
        turned = {"baseOrientation": orientation} if orientation else {}
        return pb.createMultiBody(
            0.0, shape, visual, basePosition=position, physicsClientId=self.client, **turned
        )

    def _add_model(self, index: int, model: Model) -> tuple[int, ...]:
        c = self.client
        field = f"obstacles[{index}].path"
        path = self.resolve(model.path, field)
        position, orientation = model.position, yaw_quaternion(model.yaw)
        with self._loading(field, model.path):
            if path.suffix == ".urdf":
                body = pb.loadURDF(
                    str(path),
                    basePosition=position,
                    baseOrientation=orientation,
                    useFixedBase=True,
                    flags=pb.URDF_USE_IMPLICIT_CYLINDER,
                    physicsClientId=c,
                )
                return (body,)
            bodies = tuple(pb.loadSDF(str(path), physicsClientId=c))
        if not bodies:
            raise ConfigError(
                f"{self.where}: {field}: cannot load {model.path!r}: PyBullet found no model in it"
            )
        for body in bodies:  # place the SDF's world at (position, yaw); obstacles stay put
            pos, orn = pb.getBasePositionAndOrientation(body, physicsClientId=c)
            pos, orn = pb.multiplyTransforms(position, orientation, pos, orn)
            pb.resetBasePositionAndOrientation(body, pos, orn, physicsClientId=c)
            pb.changeDynamics(body, -1, mass=0.0, physicsClientId=c)
        return bodies

    @contextlib.contextmanager
    def _loading(self, field: str, ref: str) -> Iterator[None]:
        """Run a PyBullet loader with its chatter captured; what it still refuses of a
        checked file (a mesh it cannot read, say) becomes a ConfigError."""
        prefix = f"{self.where}: {field}: cannot load {ref!r}: PyBullet"
        with bullet.captured_output() as lines:
            try:
                yield
            except pb.error as err:
                complaint = bullet.last_complaint(lines)
                raise ConfigError(f"{prefix}: {complaint or err}") from None
        unreadable = next((line for line in lines if "cannot extract mesh" in line), None)
        if unreadable is not None:
            raise ConfigError(f"{prefix}: {unreadable.split(': ', 1)[-1][:200]}")

    def _load_robot(self) -> int:
        c = self.client
        start = self.scenario.robot.start
        with self._loading("robot.urdf", self.scenario.robot.urdf):
            robot = pb.loadURDF(
                str(self.robot_path),
                basePosition=(start.x, start.y, 0.0),
                baseOrientation=yaw_quaternion(start.yaw),
                flags=pb.URDF_USE_IMPLICIT_CYLINDER | pb.URDF_USE_INERTIA_FROM_FILE,
                physicsClientId=c,
            )
        for link in range(-1, pb.getNumJoints(robot, physicsClientId=c)):
            pb.setCollisionFilterGroupMask(robot, link, ROBOT_GROUP, -1, physicsClientId=c)
        self.robot = robot
        self.set_base_pose(start.x, start.y, start.yaw)
        return robot

    # -- lookups ----------------------------------------------------------

    def resolve(self, ref: str, field: str) -> Path:
        """A model file beside the scenario file, else in robot_models/, checked."""
        what = f"{self.where}: {field}: cannot load {ref!r}"
        model = find_model_file(ref, [self.scenario.base_dir, robot_models_dir()], what=what)
        check_model_file(model, what=what)
        return model.path

    def link_names(self) -> list[str]:
        """The robot's link names; index i + 1 holds link i (index 0 is the root, -1)."""
        c = self.client
        root = pb.getBodyInfo(self.robot, physicsClientId=c)[0].decode()
        joints = range(pb.getNumJoints(self.robot, physicsClientId=c))
        names = [pb.getJointInfo(self.robot, j, physicsClientId=c)[12].decode() for j in joints]
        return [root, *names]

    def joint_names(self) -> list[str]:
        """The robot's joint names, by joint index."""
        c = self.client
        joints = range(pb.getNumJoints(self.robot, physicsClientId=c))
        return [pb.getJointInfo(self.robot, j, physicsClientId=c)[1].decode() for j in joints]

    def link_index(self, name: str, field: str = "robot.lidar_link") -> int:
        """PyBullet index of the named robot link (-1 for the root link)."""
        return self._index("link", self.link_names(), name, field) - 1

    def joint_index(self, name: str, field: str) -> int:
        """PyBullet index of the named robot joint."""
        return self._index("joint", self.joint_names(), name, field)

    def _index(self, kind: str, names: list[str], name: str, field: str) -> int:
        if name not in names:
            raise ConfigError(
                f"{self.where}: {field}: no {kind} named {name!r} in "
                f"{self.scenario.robot.urdf!r} ({kind}s: {', '.join(names) or 'none'})"
            )
        return names.index(name)

    # -- robot pose and motion ----------------------------------------------

    def link_pose(self, link: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """World position and orientation (x, y, z, w) of a robot link's URDF frame."""
        return link_frame_pose(self.client, self.robot, link)

    def base_pose(self) -> tuple[float, float, float]:
        """Planar pose (x, y, yaw) of the robot's root link frame."""
        pos, orn = self.link_pose(-1)
        return pos[0], pos[1], quaternion_yaw(orn)

    def set_base_pose(self, x: float, y: float, yaw: float) -> None:
        """Put the robot's root link frame at (x, y, 0) facing `yaw`, at rest."""
        c = self.client
        info = pb.getDynamicsInfo(self.robot, -1, physicsClientId=c)
        pos, orn = pb.multiplyTransforms((x, y, 0.0), yaw_quaternion(yaw), info[3], info[4])
        pb.resetBasePositionAndOrientation(self.robot, pos, orn, physicsClientId=c)

    def wheel_geometry(self, left: str, right: str) -> WheelGeometry:
        """Radius, track and spin signs of two wheel joints, read from the loaded URDF."""
        c = self.client
        field = "motion.mode"
        joints = (self.joint_index(left, field), self.joint_index(right, field))
        radii, positions, signs = [], [], []
        _, base_orn = self.link_pose(-1)
        base_y = np.array(pb.rotateVector(base_orn, (0.0, 1.0, 0.0)))
        for name, joint in zip((left, right), joints, strict=True):
            info = pb.getJointInfo(self.robot, joint, physicsClientId=c)
            if info[2] != pb.JOINT_REVOLUTE:
                raise ConfigError(f"{self.where}: {field}: wheel joint {name!r} does not rotate")
            radii.append(self._wheel_radius(name, joint))
            pos, orn = self.link_pose(joint)
            positions.append(np.array(pos))
            axis = np.array(pb.rotateVector(orn, info[13]))
            signs.append(1 if float(axis @ base_y) > 0 else -1)
        track = abs(float((positions[0] - positions[1]) @ base_y))
        radius = (radii[0] + radii[1]) / 2.0
        return WheelGeometry(joints[0], joints[1], radius, track, signs[0], signs[1])

    def _wheel_radius(self, name: str, joint: int) -> float:
        shapes = pb.getCollisionShapeData(self.robot, joint, physicsClientId=self.client)
        for shape in shapes:
            if shape[2] == pb.GEOM_CYLINDER:
                return float(shape[3][1])
            if shape[2] == pb.GEOM_SPHERE:
                return float(shape[3][0])
        raise ConfigError(
            f"{self.where}: motion.mode: wheels mode needs a cylinder or sphere "
            f"collision shape on the link of wheel joint {name!r}"
        )

    def set_wheel_velocities(
        self, wheels: WheelGeometry, left: float, right: float, max_torque: float
    ) -> None:
        """Command the wheel motors (rad/s of forward roll) with a torque limit (N m)."""
        pb.setJointMotorControlArray(
            self.robot,
            [wheels.left_joint, wheels.right_joint],
            pb.VELOCITY_CONTROL,
            targetVelocities=[wheels.left_sign * left, wheels.right_sign * right],
            forces=[max_torque, max_torque],
            physicsClientId=self.client,
        )

    def step(self, n: int = 1) -> None:
        """Advance the physics by n fixed steps of TIME_STEP."""
        for _ in range(n):
            pb.stepSimulation(physicsClientId=self.client)

    # -- lifetime -----------------------------------------------------------

    def close(self) -> None:
        """Give the physics client back (idempotent)."""
        if getattr(self, "client", -1) >= 0:
            bullet.release(self.client, gui=self.gui)
            self.client = -1

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def link_frame_pose(
    client: int, body: int, link: int
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """World pose of a link's URDF frame; -1 is the root, whose COM PyBullet tracks instead."""
    if link >= 0:
        state = pb.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)
        return tuple(state[4]), tuple(state[5])
    com_pos, com_orn = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    info = pb.getDynamicsInfo(body, -1, physicsClientId=client)
    inv_pos, inv_orn = pb.invertTransform(info[3], info[4])
    pos, orn = pb.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)
    return tuple(pos), tuple(orn)


def cylinder_prism(radius: float, height: float) -> tuple[list[list[float]], list[int]]:
    """A closed triangle-mesh prism around an upright cylinder centred at the origin."""
    n = cylinder_segments(radius)
    ring = [
        (radius * math.cos(2 * math.pi * k / n), radius * math.sin(2 * math.pi * k / n))
        for k in range(n)
    ]
    h = height / 2.0
    vertices = [[x, y, -h] for x, y in ring] + [[x, y, h] for x, y in ring]
    vertices += [[0.0, 0.0, -h], [0.0, 0.0, h]]
    indices: list[int] = []
    for i in range(n):
        j = (i + 1) % n
        indices += [i, j, n + j, i, n + j, n + i]  # side, outward CCW
        indices += [2 * n, j, i]  # bottom cap
        indices += [2 * n + 1, n + i, n + j]  # top cap
    return vertices, indices
