"""Shapes on the floor, as pure numbers (no pybullet): does the robot start inside an obstacle?

Refused before any simulation exists: the robot's outline is read from its
URDF and compared with the obstacles' geometrically. An ``Outline`` is a
convex polygon seen from above, rounded by a radius (a disc is one point
rounded), between two heights. The robot's are its rigid body's collision
shapes (root link and links fixed to it); mesh and plane shapes are left out.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace

from harness.scenario.urdf_chain import Matrix, Vector, rpy_matrix

__all__ = ["Outline", "disc", "overlap", "rectangle", "robot_outlines"]

Point = tuple[float, float]
_IDENTITY: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
_CIRCLE_POINTS = 32  # points on each end circle of a tilted cylinder


@dataclass(frozen=True)
class Outline:
    """A convex polygon (counter-clockwise `points`) grown by `radius`, from z_low to z_high."""

    points: tuple[Point, ...]
    radius: float
    z_low: float
    z_high: float
    label: str = ""

    def placed(self, x: float, y: float, yaw: float) -> Outline:
        """This outline (given in a body frame) for the body at (x, y, yaw)."""
        c, s = math.cos(yaw), math.sin(yaw)
        moved = tuple((x + c * px - s * py, y + s * px + c * py) for px, py in self.points)
        return replace(self, points=moved)

    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of the outline."""
        xs, ys = [p[0] for p in self.points], [p[1] for p in self.points]
        r = self.radius
        return min(xs) - r, min(ys) - r, max(xs) + r, max(ys) + r

    def contains(self, point: Point) -> float:
        """How deep `point` lies inside (m); zero or less when it is outside."""
        return self.radius - _signed_distance(self.points, (point,))


def rectangle(
    centre: Point, half_x: float, half_y: float, yaw: float, height: float, label: str = ""
) -> Outline:
    """An upright box standing on the floor, turned by `yaw`."""
    corners = ((half_x, half_y), (-half_x, half_y), (-half_x, -half_y), (half_x, -half_y))
    outline = Outline(corners, 0.0, 0.0, height, label)
    return outline.placed(centre[0], centre[1], yaw)


def disc(centre: Point, radius: float, height: float, label: str = "") -> Outline:
    """An upright cylinder standing on the floor."""
    return Outline((centre,), radius, 0.0, height, label)


def overlap(a: Outline, b: Outline) -> float:
    """How deep two solids interpenetrate (m): the least of the overlap across and in height.

    Zero or less when they only touch or are apart: then minus their distance
    across, or (when their bounding boxes are apart) minus the gap between those.
    """
    height = min(a.z_high, b.z_high) - max(a.z_low, b.z_low)
    if height <= 0:
        return height
    (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = a.bounds(), b.bounds()
    apart = max(bx0 - ax1, ax0 - bx1, by0 - ay1, ay0 - by1)
    if apart > 0:  # a cheap answer for the usual case: far apart
        return -apart
    return min(height, a.radius + b.radius - _signed_distance(a.points, b.points))


# -- convex polygons ---------------------------------------------------------


def _axes(points: Sequence[Point]) -> list[Point]:
    """Unit normals of the polygon's edges (and a segment's own direction)."""
    out: list[Point] = []
    count = len(points)
    for i in range(count if count > 2 else 1):
        (x0, y0), (x1, y1) = points[i], points[(i + 1) % count]
        length = math.hypot(x1 - x0, y1 - y0)
        if length > 0:
            out.append((-(y1 - y0) / length, (x1 - x0) / length))
            if count == 2:
                out.append(((x1 - x0) / length, (y1 - y0) / length))
    return out


def _point_segment(p: Point, a: Point, b: Point) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    along = (p[0] - a[0]) * dx + (p[1] - a[1]) * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, along / length2))
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)


def _distance(a: Sequence[Point], b: Sequence[Point]) -> float:
    """Distance between two disjoint convex polygons: some vertex to some edge."""
    best = math.inf
    for one, other in ((a, b), (b, a)):
        edges = [(other[i], other[(i + 1) % len(other)]) for i in range(len(other))]
        for p in one:
            for start, end in edges:
                best = min(best, _point_segment(p, start, end))
    return best


def _signed_distance(a: Sequence[Point], b: Sequence[Point]) -> float:
    """Distance between convex polygons `a` and `b`; minus the penetration depth if they overlap.

    Separating axes: the edge normals of both (exact in 2D for convex shapes).
    """
    gap = -math.inf
    for ax, ay in _axes(a) + _axes(b):
        a_proj = [ax * x + ay * y for x, y in a]
        b_proj = [ax * x + ay * y for x, y in b]
        gap = max(gap, min(b_proj) - max(a_proj), min(a_proj) - max(b_proj))
    if gap == -math.inf:  # two points
        return math.dist(a[0], b[0])
    return _distance(a, b) if gap > 0 else gap


def _hull(points: Iterable[Point]) -> tuple[Point, ...]:
    """Convex hull, counter-clockwise (Andrew's monotone chain); 1 or 2 points if degenerate."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return tuple(pts)

    def cross(o: Point, a: Point, b: Point) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[Point] = []
    upper: list[Point] = []
    for chain, seq in ((lower, pts), (upper, reversed(pts))):
        for p in seq:
            while len(chain) >= 2 and cross(chain[-2], chain[-1], p) <= 0:
                chain.pop()
            chain.append(p)
    return tuple(lower[:-1] + upper[:-1])


# -- the robot's URDF --------------------------------------------------------


def _floats(text: str | None, default: Vector) -> Vector:
    """Three numbers from a URDF attribute (checked in scenario.model_files), or `default`."""
    parts = (text or "").split()
    return (float(parts[0]), float(parts[1]), float(parts[2])) if len(parts) == 3 else default


def _apply(rotation: Matrix, v: Vector) -> Vector:
    return (
        rotation[0][0] * v[0] + rotation[0][1] * v[1] + rotation[0][2] * v[2],
        rotation[1][0] * v[0] + rotation[1][1] * v[1] + rotation[1][2] * v[2],
        rotation[2][0] * v[0] + rotation[2][1] * v[1] + rotation[2][2] * v[2],
    )


Transform = tuple[Vector, Matrix]


def _compose(parent: Transform, child: Transform) -> Transform:
    """`child` (given in the parent's frame) in the frame `parent` is given in."""
    (t1, r1), (t2, r2) = parent, child
    moved = _apply(r1, t2)
    rows = [tuple(sum(r1[i][k] * r2[k][j] for k in range(3)) for j in range(3)) for i in range(3)]
    rotation: Matrix = (rows[0], rows[1], rows[2])  # type: ignore[assignment]
    return (t1[0] + moved[0], t1[1] + moved[1], t1[2] + moved[2]), rotation


def _origin(element: ET.Element) -> Transform:
    origin = element.find("origin")
    if origin is None:
        return (0.0, 0.0, 0.0), _IDENTITY
    xyz = _floats(origin.get("xyz"), (0.0, 0.0, 0.0))
    return xyz, rpy_matrix(*_floats(origin.get("rpy"), (0.0, 0.0, 0.0)))


def _shape_outline(shape: ET.Element, pose: Transform, label: str) -> Outline | None:
    """The outline of one URDF collision shape at `pose` (robot frame); None if not read."""
    (cx, cy, cz), rotation = pose
    axis = (rotation[0][2], rotation[1][2], rotation[2][2])  # the shape's own z axis
    tilt = math.sqrt(max(0.0, 1.0 - axis[2] ** 2))  # sine of the axis' angle to vertical
    if shape.tag == "box":
        hx, hy, hz = (v / 2.0 for v in _floats(shape.get("size"), (0.0, 0.0, 0.0)))
        corners = [
            _apply(rotation, (sx * hx, sy * hy, sz * hz))
            for sx in (-1, 1)
            for sy in (-1, 1)
            for sz in (-1, 1)
        ]
        zs = [cz + c[2] for c in corners]
        return Outline(_hull((cx + c[0], cy + c[1]) for c in corners), 0.0, min(zs), max(zs), label)
    radius = float(shape.get("radius") or 0.0)
    if shape.tag == "sphere":
        return Outline(((cx, cy),), radius, cz - radius, cz + radius, label)
    if shape.tag not in ("cylinder", "capsule"):
        return None  # mesh, plane: extent not read
    half = float(shape.get("length") or 0.0) / 2.0
    ends = [(cx + k * half * axis[0], cy + k * half * axis[1]) for k in (-1, 1)]
    if shape.tag == "capsule":
        reach = abs(axis[2]) * half + radius
        return Outline(_hull(ends), radius, cz - reach, cz + reach, label)
    reach = abs(axis[2]) * half + radius * tilt
    if tilt < 1e-9:  # upright: a disc seen from above
        return Outline(((cx, cy),), radius, cz - reach, cz + reach, label)
    rim = []
    for k in (-1, 1):
        for i in range(_CIRCLE_POINTS):
            a = 2 * math.pi * i / _CIRCLE_POINTS
            local = (radius * math.cos(a), radius * math.sin(a), k * half)
            dx, dy, _ = _apply(rotation, local)
            rim.append((cx + dx, cy + dy))
    return Outline(_hull(rim), 0.0, cz - reach, cz + reach, label)


def robot_outlines(root: ET.Element) -> list[Outline]:
    """Outlines of a checked URDF's rigid body, in its root link's frame (z = 0 on the floor).

    The rigid body is the root link and the links joined to it by fixed
    joints; each collision box, cylinder, capsule and sphere counts.
    """
    links = {link.get("name", ""): link for link in root.findall("link")}
    children: dict[str, list[ET.Element]] = {}
    for joint in root.findall("joint"):
        parent = joint.find("parent")
        if parent is not None:
            children.setdefault(parent.get("link", ""), []).append(joint)
    child_names = {
        child.get("link", "")
        for joint in root.findall("joint")
        if (child := joint.find("child")) is not None
    }
    roots = [name for name in links if name not in child_names]
    origin: Transform = ((0.0, 0.0, 0.0), _IDENTITY)
    pending: list[tuple[str, Transform]] = [(roots[0], origin)] if roots else []
    outlines: list[Outline] = []
    while pending:
        name, pose = pending.pop()
        for collision in links[name].findall("collision"):
            geometry = collision.find("geometry")
            for shape in geometry if geometry is not None else ():
                label = f"link {name!r} collision {shape.tag}"
                outline = _shape_outline(shape, _compose(pose, _origin(collision)), label)
                if outline is not None:
                    outlines.append(outline)
        for joint in children.get(name, []):
            child = joint.find("child")
            if joint.get("type") == "fixed" and child is not None and child.get("link") in links:
                pending.append((child.get("link", ""), _compose(pose, _origin(joint))))
    return outlines
