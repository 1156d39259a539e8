"""The PyBullet world: the FOSSBot URDF, obstacles, model files and their errors."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from sim_scenarios import make_scenario

from harness.cli import build_parser, flag_names
from harness.errors import ConfigError
from harness.option_names import speaking
from harness.scenario.files import parse_scenario
from harness.sim.bullet import pb
from harness.sim.lidar import LidarModel
from harness.sim.world import World, robot_models_dir

URDF = robot_models_dir() / "fossbot_v2.urdf"

OTHER_ROBOT = """<?xml version="1.0"?>
<robot name="other">
  <link name="chassis">
    <inertial>
      <mass value="1.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.3 0.2 0.2"/></geometry></collision>
  </link>
  <joint name="laser_mount" type="fixed">
    <parent link="chassis"/><child link="laser"/><origin xyz="0.1 0 0.3" rpy="0 0 0"/>
  </joint>
  <link name="laser">
    <inertial>
      <mass value="0.1"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/>
    </inertial>
    <collision><geometry><cylinder radius="0.04" length="0.05"/></geometry></collision>
  </link>
</robot>
"""

CRATE_URDF = """<?xml version="1.0"?>
<robot name="crate">
  <link name="body">
    <inertial>
      <mass value="1.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.4 0.2 0.4"/></geometry></collision>
  </link>
</robot>
"""

POST_SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="post">
    <static>true</static>
    <pose>0.5 0 0.25 0 0 0</pose>
    <link name="post">
      <collision name="c"><geometry><box><size>0.2 0.2 0.5</size></box></geometry></collision>
    </link>
  </model>
</sdf>
"""


def test_urdf_masses_sum_to_two_kilograms():
    """Every link's mass, as written and as PyBullet loads it, adds up to 2.000 kg."""
    masses = [float(m.get("value")) for m in ET.parse(URDF).getroot().iter("mass")]
    assert sum(masses) == pytest.approx(2.0, abs=1e-9)
    assert all(m > 0 for m in masses)  # a massless root would be static in PyBullet


def test_urdf_dimensions_as_loaded():
    """Wheel radius and track, LIDAR height and offset, caster position, all as in FACTS.md."""
    with World(make_scenario()) as world:
        c, robot = world.client, world.robot
        links = range(-1, pb.getNumJoints(robot, physicsClientId=c))
        total = sum(pb.getDynamicsInfo(robot, i, physicsClientId=c)[0] for i in links)
        assert total == pytest.approx(2.0, abs=1e-9)
        wheels = world.wheel_geometry("left_wheel_joint", "right_wheel_joint")
        assert wheels.radius == pytest.approx(0.03524, abs=1e-6)
        assert wheels.track == pytest.approx(0.1866, abs=1e-6)
        assert (wheels.left_sign, wheels.right_sign) == (1, 1)
        lidar_pos, lidar_orn = world.link_pose(world.lidar_link)
        assert lidar_pos[2] == pytest.approx(0.155, abs=0.005)
        assert lidar_pos[0] == pytest.approx(-0.016, abs=1e-6)
        assert lidar_orn == pytest.approx((0, 0, 0, 1), abs=1e-12)
        # The A1's own frame: where the scan frame is, its zero turned to the right.
        device_pos, device_orn = world.link_pose(world.link_index("lidar_device_frame"))
        assert device_pos == pytest.approx(lidar_pos, abs=1e-9)
        half = math.sqrt(0.5)
        assert device_orn == pytest.approx((0, 0, -half, half), abs=1e-7)
        caster = world.link_index("caster")
        # PyBullet keeps URDF joint origins in single precision: 1e-6 m is exact here
        assert world.link_pose(caster)[0] == pytest.approx((-0.095, 0.0, 0.015), abs=1e-6)
        shape = pb.getCollisionShapeData(robot, caster, physicsClientId=c)[0]
        assert shape[2] == pb.GEOM_SPHERE and shape[3][0] == pytest.approx(0.015)
        root_pos, _ = world.link_pose(-1)
        assert root_pos == pytest.approx((0, 0, 0), abs=1e-12)
        assert world.link_names()[:2] == ["base_footprint", "base_link"]


def test_robot_collision_geometry_stays_below_the_scan_plane():
    """No link's collision box reaches the scan plane, so no beam can graze the robot."""
    with World(make_scenario(start=(0, 0, 0.7))) as world:
        c = world.client
        links = range(-1, pb.getNumJoints(world.robot, physicsClientId=c))
        # Frames without geometry (the root, the scan and device frames) have a point AABB.
        solid = [i for i in links if pb.getCollisionShapeData(world.robot, i, physicsClientId=c)]
        tops = [pb.getAABB(world.robot, i, physicsClientId=c)[1][2] for i in solid]
        names = world.link_names()
        assert names[world.lidar_link + 1] == "lidar_scan_frame"
        frames = {names[i + 1] for i in links if i not in solid}
        assert frames == {"base_footprint", "lidar_scan_frame", "lidar_device_frame"}
    assert max(tops) < 0.155 - 0.01


def test_robot_starts_at_the_scenario_pose():
    """The base footprint is put at start (x, y, yaw) on the ground."""
    with World(make_scenario(start=(1.5, -2.0, 2.8))) as world:
        assert world.base_pose() == pytest.approx((1.5, -2.0, 2.8), abs=1e-7)
        world.set_base_pose(0.1, 0.2, -3.0)
        assert world.base_pose() == pytest.approx((0.1, 0.2, -3.0), abs=1e-7)


def test_another_urdf_with_its_own_lidar_link_name(tmp_path):
    """Any URDF with a named LIDAR link works, found next to the scenario file."""
    (tmp_path / "other.urdf").write_text(OTHER_ROBOT)
    scenario = make_scenario(
        robot={"urdf": "other.urdf", "lidar_link": "laser"},
        obstacles=[{"type": "wall", "start": [2.0, -1], "end": [2.0, 1], "height": 1.0}],
        source=str(tmp_path / "scenario.yaml"),
    )
    with World(scenario) as world:
        assert world.robot_path == tmp_path / "other.urdf"
        assert world.link_pose(world.lidar_link)[0] == pytest.approx((0.1, 0, 0.3))
        truth = LidarModel.for_world(world, scenario.lidar_spec).truth()
    assert truth.min() == pytest.approx(2.0 - 0.025 - 0.1, abs=1e-3)


def test_root_link_can_be_the_lidar_link(tmp_path):
    """A LIDAR on the root link is found (index -1) and scans from the root's frame."""
    (tmp_path / "other.urdf").write_text(OTHER_ROBOT)
    scenario = make_scenario(
        robot={"urdf": "other.urdf", "lidar_link": "chassis"},
        obstacles=[{"type": "wall", "start": [2.0, -1], "end": [2.0, 1]}],
        source=str(tmp_path / "s.yaml"),
    )
    with World(scenario) as world:
        assert world.lidar_link == -1
        truth = LidarModel.for_world(world, scenario.lidar_spec).truth()
    assert truth.min() == pytest.approx(2.0 - 0.025, abs=1e-3)


def test_missing_lidar_link_lists_the_links():
    """A wrong lidar_link names the file and field and lists the links there are."""
    with pytest.raises(ConfigError) as err:
        World(make_scenario(robot={"lidar_link": "laser"}))
    msg = str(err.value)
    assert msg.startswith("test.yaml: robot.lidar_link: no link named 'laser' in 'fossbot_v2.urdf'")
    assert "lidar_scan_frame" in msg and "base_footprint" in msg


def test_missing_robot_file(tmp_path):
    """A robot URDF that is nowhere to be found names the field and where it looked."""
    with pytest.raises(ConfigError) as err:
        World(make_scenario(robot={"urdf": "nope.urdf"}, source=str(tmp_path / "s.yaml")))
    msg = str(err.value)
    assert msg.startswith(
        f"{tmp_path / 's.yaml'}: robot.urdf: cannot load 'nope.urdf': no such file"
    )
    assert str(tmp_path) in msg and str(robot_models_dir()) in msg


def test_missing_model_file_names_the_obstacle():
    """A missing model file names obstacles[i].path."""
    obstacles = [
        {"type": "wall", "start": [1, 0], "end": [1, 1]},
        {"type": "model", "path": "x.urdf"},
    ]
    with pytest.raises(
        ConfigError, match=r"^test\.yaml: obstacles\[1\]\.path: cannot load 'x\.urdf': no such file"
    ):
        World(make_scenario(obstacles=obstacles))


@pytest.mark.parametrize("name", ["bad.urdf", "bad.sdf"])
def test_unloadable_model_file_names_the_obstacle(tmp_path, name):
    """A file PyBullet cannot parse is a ConfigError naming the field, not a crash."""
    (tmp_path / name).write_text("<robot><link></robot>")
    scenario = make_scenario(
        obstacles=[{"type": "model", "path": name}], source=str(tmp_path / "s.yaml")
    )
    with pytest.raises(
        ConfigError, match=rf"s\.yaml: obstacles\[0\]\.path: cannot load '{name}': not well-formed"
    ):
        World(scenario)


def test_unloadable_robot_file(tmp_path):
    """A robot URDF PyBullet cannot parse names robot.urdf."""
    (tmp_path / "bad.urdf").write_text("<robot><link></robot>")
    with pytest.raises(
        ConfigError, match=r"s\.yaml: robot\.urdf: cannot load 'bad\.urdf': not well-formed"
    ):
        World(make_scenario(robot={"urdf": "bad.urdf"}, source=str(tmp_path / "s.yaml")))


def test_model_obstacles_urdf_and_sdf_are_placed_and_seen(tmp_path):
    """URDF and SDF models load relative to the scenario, at their position and yaw, fixed."""
    (tmp_path / "crate.urdf").write_text(CRATE_URDF)
    (tmp_path / "post.sdf").write_text(POST_SDF)
    scenario = make_scenario(
        obstacles=[
            {
                "type": "model",
                "path": "crate.urdf",
                "position": [1.0, 0.0, 0.0],
                "yaw": math.pi / 2,
            },
            # the SDF's own pose (0.5, 0) is carried by yaw pi/2 and shifted to (0, 1)+(0, 0.5)
            {"type": "model", "path": "post.sdf", "position": [0.0, 1.0, 0.0], "yaw": math.pi / 2},
        ],
        source=str(tmp_path / "s.yaml"),
    )
    with World(scenario) as world:
        truth = LidarModel.for_world(world, scenario.lidar_spec).truth()
        post = world.obstacle_bodies[1][0]
        assert pb.getBasePositionAndOrientation(post, physicsClientId=world.client)[0] == (
            pytest.approx((0.0, 1.5, 0.25), abs=1e-9)
        )
        world.step(48)  # static: gravity does not move them
        assert pb.getBasePositionAndOrientation(post, physicsClientId=world.client)[0] == (
            pytest.approx((0.0, 1.5, 0.25), abs=1e-9)
        )
    angles = scenario.lidar_spec.angle_min + np.arange(360) * scenario.lidar_spec.angle_increment
    ahead = truth[np.abs(angles) < 0.02].min()  # the 0.4 x 0.2 crate turned by yaw: 0.1 deep
    assert ahead == pytest.approx(1.0 + 0.016 - 0.1, abs=1e-3)
    left = truth[np.abs(angles - math.pi / 2) < 0.01].min()
    assert left == pytest.approx(1.5 - 0.1, abs=1e-3)


def test_robot_models_are_found_in_robot_models_dir():
    """Without a scenario folder, model paths fall back to robot_models/."""
    scenario = make_scenario(
        obstacles=[{"type": "model", "path": "fossbot_v2.urdf", "position": [1, 0, 0]}]
    )
    with World(scenario) as world:
        assert len(world.obstacle_bodies) == 1


def test_gui_without_display_is_a_config_error(monkeypatch):
    """--gui on a headless machine is the user's to fix, not a crash."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr("sys.platform", "linux")
    with (
        speaking(flag_names(build_parser())),  # as the CLI names the option
        pytest.raises(ConfigError, match="^--gui needs a display$"),
    ):
        World(make_scenario(), gui=True)


def test_worlds_coexist_in_one_process():
    """Two worlds with their own clients do not see each other's obstacles."""
    near = make_scenario(obstacles=[{"type": "wall", "start": [1, -1], "end": [1, 1]}])
    far = make_scenario(obstacles=[{"type": "wall", "start": [3, -1], "end": [3, 1]}])
    with World(near) as a, World(far) as b:
        assert a.client != b.client
        ta = LidarModel.for_world(a, near.lidar_spec).truth()
        tb = LidarModel.for_world(b, far.lidar_spec).truth()
    assert ta.min() == pytest.approx(0.991, abs=1e-3)
    assert tb.min() == pytest.approx(2.991, abs=1e-3)


def test_close_is_idempotent():
    """close() twice is harmless, and the client is gone or empty after it (kept for the
    next world, which then starts from nothing)."""
    world = World(make_scenario())
    client = world.client
    world.close()
    world.close()
    assert world.client == -1
    kept = pb.isConnected(physicsClientId=client)
    assert not kept or pb.getNumBodies(physicsClientId=client) == 0
    other = World(make_scenario())
    try:
        assert other.client == client or not kept  # the spare client is used again
        assert pb.getNumBodies(physicsClientId=other.client) == len(other.obstacle_bodies) + 2
    finally:
        other.close()


def test_building_the_world_is_deterministic(tmp_path):
    """The same scenario builds the same bodies, poses and shapes."""
    scenario = parse_scenario(
        {
            "description": "determinism",
            "obstacles": [
                {"type": "wall", "start": [1, -1], "end": [2, 1]},
                {"type": "box", "position": [-1, 0], "size": [0.2, 0.3, 0.4], "yaw": 0.3},
                {"type": "cylinder", "position": [0, -1], "radius": 0.1},
            ],
            "motion": {"segments": [{"until": {"duration": 1}}]},
        },
        source=str(Path(tmp_path) / "d.yaml"),
    )

    def snapshot() -> list:
        with World(scenario) as w:
            n = pb.getNumBodies(physicsClientId=w.client)
            return [
                (
                    pb.getBasePositionAndOrientation(i, physicsClientId=w.client),
                    pb.getAABB(i, physicsClientId=w.client),
                )
                for i in range(n)
            ]

    assert snapshot() == snapshot()
