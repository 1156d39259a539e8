"""The simulated LIDAR against geometry worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_scenarios import make_scenario

from harness.lidar.spec import PRESETS
from harness.sim import lidar as lidar_module
from harness.sim.lidar import LidarModel, beam_angles
from harness.sim.world import World

LIDAR_BACK = 0.016  # m, the FOSSBot LIDAR sits this far behind the base origin
MM = 1e-3


def lidar_origin(x: float, y: float, yaw: float) -> np.ndarray:
    """Where the FOSSBot's scan frame is for a base pose (x, y, yaw)."""
    return np.array([x - LIDAR_BACK * math.cos(yaw), y - LIDAR_BACK * math.sin(yaw)])


def ray_circle(o: np.ndarray, angle: float, centre: np.ndarray, radius: float) -> float:
    """Distance from o along the world direction `angle` to a circle; inf on a miss."""
    d = np.array([math.cos(angle), math.sin(angle)])
    rel = centre - o
    along = d @ rel
    miss2 = rel @ rel - along**2
    if along <= 0 or miss2 > radius**2:
        return math.inf
    return along - math.sqrt(radius**2 - miss2)


def wrap(a: np.ndarray | float) -> np.ndarray | float:
    return np.remainder(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


def scan(scenario, spec=None) -> tuple[np.ndarray, np.ndarray]:
    """(truth, beam angles) of one scan at the scenario's start pose."""
    spec = spec or scenario.lidar_spec
    with World(scenario) as world:
        return LidarModel.for_world(world, spec).truth(), beam_angles(spec)


def test_wall_distance_and_angle_match_geometry():
    """Every beam hitting an oblique wall measures the analytic distance to its face."""
    start, end, thickness = (2.0, -3.0), (2.5, 3.0), 0.05
    pose = (0.3, -0.2, 0.4)
    truth, angles = scan(
        make_scenario(
            obstacles=[{"type": "wall", "start": start, "end": end, "thickness": thickness}],
            start=pose,
        )
    )
    o = lidar_origin(*pose)
    a, b = np.array(start), np.array(end)
    along = (b - a) / np.linalg.norm(b - a)
    normal = np.array([-along[1], along[0]])
    if normal @ (o - a) < 0:
        normal = -normal  # points from the wall towards the LIDAR
    face = a + normal * thickness / 2  # a point on the near face
    gap = normal @ (o - face)
    directions = np.stack([np.cos(pose[2] + angles), np.sin(pose[2] + angles)], axis=1)
    facing = directions @ normal
    with np.errstate(divide="ignore"):
        expected = np.where(facing < -1e-9, gap / -facing, np.inf)
    hit_at = o + directions * np.where(np.isfinite(expected), expected, 0)[:, None]
    s = (hit_at - a) @ along
    inner = np.isfinite(expected) & (s > 0.05) & (s < np.linalg.norm(b - a) - 0.05)
    assert inner.sum() > 40
    np.testing.assert_allclose(truth[inner], expected[inner], atol=MM)
    foot_bearing = math.atan2(-normal[1], -normal[0]) - pose[2]
    nearest = int(np.argmin(truth))
    assert truth[nearest] == pytest.approx(gap, abs=MM)
    assert abs(wrap(angles[nearest] - foot_bearing)) <= PRESETS["gazebo"].angle_increment


def test_cylinder_distance_and_angle_match_geometry():
    """A post reads as the analytic ray-circle intersection, nearest beam towards its centre."""
    centre, radius = np.array([1.2, 0.7]), 0.15
    pose = (0.1, 0.2, -0.3)
    truth, angles = scan(
        make_scenario(
            obstacles=[{"type": "cylinder", "position": centre.tolist(), "radius": radius}],
            start=pose,
        )
    )
    o = lidar_origin(*pose)
    rel = centre - o
    directions = np.stack([np.cos(pose[2] + angles), np.sin(pose[2] + angles)], axis=1)
    along = directions @ rel
    miss = np.sqrt(np.maximum(rel @ rel - along**2, 0.0))
    clear = (along > 0) & (miss < radius - 0.01)  # well inside the silhouette
    expected = along - np.sqrt(radius**2 - np.minimum(miss, radius) ** 2)
    assert clear.sum() >= 5
    np.testing.assert_allclose(truth[clear], expected[clear], atol=MM)
    assert np.all(np.isinf(truth[(along <= 0) | (miss > radius + 0.01)]))
    nearest = int(np.argmin(truth))
    assert truth[nearest] == pytest.approx(np.linalg.norm(rel) - radius, abs=MM)
    bearing = math.atan2(rel[1], rel[0]) - pose[2]
    assert abs(wrap(angles[nearest] - bearing)) <= PRESETS["gazebo"].angle_increment


@pytest.mark.parametrize("name", sorted(PRESETS))
@pytest.mark.parametrize("bearing_deg", [30.0, -60.0, 135.0])
def test_preset_beam_layout_puts_an_obstacle_at_its_bearing(name, bearing_deg):
    """Each preset's beam i points at angle_min + i * increment, CCW from the LIDAR's +x."""
    spec = PRESETS[name]
    angles = beam_angles(spec)
    assert angles.size == spec.samples
    assert angles[0] == spec.angle_min
    assert angles[-1] == pytest.approx(spec.angle_max)
    bearing = math.radians(bearing_deg)
    o = lidar_origin(0, 0, 0)
    centre = o + 1.5 * np.array([math.cos(bearing), math.sin(bearing)])
    truth, _ = scan(
        make_scenario(
            obstacles=[{"type": "cylinder", "position": centre.tolist(), "radius": 0.05}],
            lidar={"preset": name},
        )
    )
    nearest = int(np.argmin(truth))
    assert truth[nearest] == pytest.approx(ray_circle(o, angles[nearest], centre, 0.05), abs=MM)
    assert abs(wrap(angles[nearest] - bearing)) <= spec.angle_increment / 2 + 1e-9


def test_batch_equals_per_ray_reference():
    """One rayTestBatch per scan gives what one rayTest per beam gives."""
    scenario = make_scenario(
        obstacles=[
            {"type": "wall", "start": [-2, 2], "end": [3, 1.5]},
            {"type": "box", "position": [1.0, -0.8], "size": [0.3, 0.5, 0.4], "yaw": 0.7},
            {"type": "cylinder", "position": [-1.0, -0.5], "radius": 0.2},
        ],
        start=(0.2, 0.1, 2.5),
        lidar={"preset": "ld19"},
    )
    with World(scenario) as world:
        model = LidarModel.for_world(world, scenario.lidar_spec)
        batch, reference = model.truth(), model.truth_reference()
    assert batch.dtype == np.float64 and batch.shape == (450,)
    assert np.isfinite(batch).sum() > 100
    np.testing.assert_array_equal(np.isinf(batch), np.isinf(reference))
    np.testing.assert_allclose(batch, reference, atol=1e-9)


def test_batches_are_split_at_the_ray_cap(monkeypatch):
    """Scans longer than the batch cap are cast in chunks with the same result."""
    scenario = make_scenario(obstacles=[{"type": "wall", "start": [1, -5], "end": [1, 5]}])
    with World(scenario) as world:
        model = LidarModel.for_world(world, scenario.lidar_spec)
        whole = model.truth()
        monkeypatch.setattr(lidar_module, "MAX_RAYS_PER_BATCH", 7)
        np.testing.assert_array_equal(model.truth(), whole)
    assert lidar_module.MAX_RAYS_PER_BATCH == 7 and np.isfinite(whole).sum() > 100


def test_largest_allowed_scan_gets_hits():
    """16383 beams (the rayTestBatch cap) still return real hits, not silence."""
    scenario = make_scenario(
        obstacles=[{"type": "wall", "start": [1, -5], "end": [1, 5]}],
        lidar={"preset": "gazebo", "samples": 16383, "angle_increment": 2 * math.pi / 16383},
    )
    truth, _ = scan(scenario)
    assert truth.size == 16383
    assert np.isfinite(truth).sum() > 16383 // 3


def test_robot_alone_sees_nothing():
    """No self-hits: in an empty world every beam is inf, even without the ray mask."""
    scenario = make_scenario(start=(0.5, -0.3, 1.0))
    with World(scenario) as world:
        masked = LidarModel.for_world(world, scenario.lidar_spec).truth()
        unmasked = LidarModel(world.client, world.robot, world.lidar_link, scenario.lidar_spec)
        assert np.all(np.isposinf(unmasked.truth()))
    assert np.all(np.isposinf(masked))


@pytest.mark.parametrize("name", sorted(PRESETS))
@pytest.mark.parametrize("yaw", [0.0, math.pi / 2, -2.5])
def test_wall_on_the_left_appears_near_plus_half_pi(name, yaw):
    """Beams turn with the robot: a wall to the robot's left is nearest at +pi/2."""
    left = np.array([-math.sin(yaw), math.cos(yaw)])
    ahead = np.array([math.cos(yaw), math.sin(yaw)])
    o = lidar_origin(0, 0, yaw)
    mid = o + 0.8 * left
    wall = {
        "type": "wall",
        "start": (mid - 3 * ahead).tolist(),
        "end": (mid + 3 * ahead).tolist(),
        "thickness": 0.1,
    }
    spec = PRESETS[name]
    truth, angles = scan(make_scenario(obstacles=[wall], start=(0, 0, yaw), lidar={"preset": name}))
    nearest = int(np.argmin(truth))
    assert truth[nearest] == pytest.approx(0.75 / math.cos(angles[nearest] - math.pi / 2), abs=MM)
    assert abs(wrap(angles[nearest] - math.pi / 2)) <= spec.angle_increment / 2 + 1e-9


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_obstacle_straight_behind_sits_on_the_pi_seam(name):
    """An obstacle behind the robot reads at +-pi, at both ends of a -pi..pi scan."""
    spec = PRESETS[name]
    o = lidar_origin(0, 0, 0)
    centre = o + np.array([-1.0, 0.0])
    truth, angles = scan(
        make_scenario(
            obstacles=[{"type": "cylinder", "position": centre.tolist(), "radius": 0.1}],
            lidar={"preset": name},
        )
    )
    nearest = int(np.argmin(truth))
    assert truth[nearest] == pytest.approx(ray_circle(o, angles[nearest], centre, 0.1), abs=MM)
    assert abs(abs(wrap(angles[nearest])) - math.pi) <= spec.angle_increment / 2 + 1e-9
    if name == "gazebo":  # closed layout: the first and last beam both point backwards
        assert truth[0] == pytest.approx(0.9, abs=MM)
        assert truth[-1] == pytest.approx(truth[0], abs=1e-9)


def test_ranges_below_range_min_are_true_distances():
    """Truth keeps a too-close return as its distance; conventions come later."""
    face = 0.1 - LIDAR_BACK  # wall face 0.1 m ahead of the LIDAR, inside range_min 0.12
    wall = {"type": "wall", "start": [face + 0.025, -1], "end": [face + 0.025, 1]}
    truth, angles = scan(make_scenario(obstacles=[wall]))
    assert truth.min() == pytest.approx(0.1, abs=MM)
    assert truth.min() < PRESETS["gazebo"].range_min


def test_nothing_beyond_range_max():
    """A wall just past range_max is inf; just inside it is seen."""
    far = {"type": "wall", "start": [5.0, -1], "end": [5.0, 1]}
    base = {"preset": "gazebo", "range_max": 4.9}
    truth, _ = scan(make_scenario(obstacles=[far], lidar=base))
    assert np.all(np.isinf(truth))
    truth, _ = scan(make_scenario(obstacles=[far], lidar={**base, "range_max": 5.1}))
    assert truth.min() == pytest.approx(5.0 - 0.025 + LIDAR_BACK, abs=MM)
