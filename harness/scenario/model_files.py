"""Model files a scenario names: where they may live, and whether PyBullet can take them.

Where: paths relative to the scenario's folder, else ``robot_models/``; the
file (symlinks followed) and every mesh it uses must lie inside the folder
it was found in, so a scenario from elsewhere cannot make the harness read
``/etc/passwd``.

What: PyBullet's parsers print on stdout and crash the process on some
broken files (two root links, a mesh path naming a folder, an SDF of two
links without a joint), so each file is read here first, bounded, and
checked for what PyBullet needs. Pure (xml.etree): checked at load, before
any node starts.
"""

from __future__ import annotations

import math
import os
import stat
import struct
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path, PurePosixPath

from harness.errors import ConfigError
from harness.safe_text import shown

__all__ = [
    "MAX_MESH_BYTES", "MAX_MODEL_BYTES", "MESH_SUFFIXES", "ModelFile", "ModelParts",
    "check_model_file", "exists", "find_model_file", "parse_xml", "robot_models_dir",
]  # fmt: skip

MAX_MODEL_BYTES = 5 << 20  # a URDF/SDF file; the FOSSBot's is 7 kB
MAX_MESH_BYTES = 50 << 20  # one mesh file
MESH_SUFFIXES = (".stl", ".obj", ".dae")  # what PyBullet's mesh loader reads
SNIFF_BYTES = 64 << 10  # how much of a mesh is read to see what it is
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar", "spherical")
SHAPES = ("box", "cylinder", "sphere", "capsule", "mesh", "plane")  # URDF's and SDF's
# The sizes each solid shape must give (name, how many numbers), every one positive.
_SIZES = {
    "box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)),
    "capsule": (("radius", 1), ("length", 1)), "sphere": (("radius", 1),),
}  # fmt: skip


def robot_models_dir() -> Path:
    """Folder of the shipped robot and world models (``robot_models/``)."""
    return Path(str(resources.files("harness.robot_models")))


@dataclass(frozen=True)
class ModelParts:
    """What a checked URDF holds, for checks that name its parts (empty for SDF)."""

    links: tuple[str, ...] = ()
    joints: tuple[tuple[str, str], ...] = ()  # (name, type)


@dataclass(frozen=True)
class ModelFile:
    """A model file found for a scenario, and the folder it must stay inside."""

    path: Path  # resolved (symlinks followed)
    root: Path  # resolved folder it was found in: the scenario's folder or robot_models/


def _inside(path: Path, root: Path) -> bool:
    return path == root or root in path.parents


def _plain_relative(ref: str, what: str) -> PurePosixPath:
    """`ref` as a relative path that does not climb out of its folder, or ConfigError."""
    if not ref.strip() or "\0" in ref:
        raise ConfigError(f"{what}: empty or not a path")
    given = PurePosixPath(ref)
    if given.is_absolute() or ref.startswith("~"):
        raise ConfigError(
            f"{what}: absolute paths are not allowed (give it relative to the folder)"
        )
    normal = PurePosixPath(os.path.normpath(ref))
    if normal.parts and normal.parts[0] == "..":
        raise ConfigError(f"{what}: climbs out of its folder with '..'")
    return normal


def exists(path: Path, *, follow_symlinks: bool = False) -> bool:
    """Whether anything is there; a name the OS refuses (too long, a NUL) is nothing."""
    try:
        os.stat(path, follow_symlinks=follow_symlinks)
    except (OSError, ValueError):
        return False
    return True


def _resolved_inside(candidate: Path, root: Path, what: str) -> Path:
    """The real path of `candidate`; ConfigError if it leaves `root` or is not a file."""
    try:
        real = candidate.resolve(strict=True)
    except (OSError, RuntimeError) as err:  # RuntimeError: a symlink loop (Python < 3.13)
        where = shown(str(candidate))
        raise ConfigError(f"{what}: cannot resolve {where}: {_reason(err)}") from None
    if not _inside(real, root):
        raise ConfigError(
            f"{what}: resolves to {shown(str(real))}, outside {shown(str(root))} "
            "(model files must stay inside the scenario's folder or robot_models/)"
        )
    try:
        mode = os.stat(real).st_mode
    except OSError as err:
        raise ConfigError(f"{what}: cannot read {shown(str(real))}: {_reason(err)}") from None
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        raise ConfigError(f"{what}: {shown(str(real))} is {kind}")
    return real


def _reason(err: BaseException) -> str:
    return getattr(err, "strerror", None) or str(err) or type(err).__name__


def find_model_file(ref: str, folders: Sequence[Path | None], *, what: str = "") -> ModelFile:
    """The model file `ref` names: in the first of `folders` that has it, inside that folder.

    `what` prefixes the messages (e.g. ``cannot load 'x.urdf'``); None
    folders (a scenario built in code) are skipped.
    """
    label = what or repr(ref)
    relative = _plain_relative(ref, label)
    tried: list[str] = []
    for folder in folders:
        if folder is None:
            continue
        tried.append(shown(str(folder)))
        candidate = folder / relative
        if exists(candidate):
            root = folder.resolve()
            return ModelFile(_resolved_inside(candidate, root, label), root)
    raise ConfigError(f"{label}: no such file (looked in {', '.join(tried)})")


# -- reading ---------------------------------------------------------------


def _read_bounded(path: Path, limit: int, what: str) -> bytes:
    """At most `limit` bytes of a regular file; ConfigError beyond that."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as err:
        raise ConfigError(f"{what}: cannot read: {_reason(err)}") from None
    if len(data) > limit:
        raise ConfigError(f"{what}: larger than {limit >> 20} MiB")
    return data


def parse_xml(path: Path, what: str) -> ET.Element:
    """A URDF/SDF file's XML, bounded in size and without DTDs; ConfigError names `what`."""
    data = _read_bounded(path, MAX_MODEL_BYTES, what)
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise ConfigError(f"{what}: DOCTYPE and ENTITY declarations are not allowed")
    try:
        return ET.fromstring(data)
    except ET.ParseError as err:
        raise ConfigError(f"{what}: not well-formed XML: {err}") from None


# -- numbers ---------------------------------------------------------------


def _numbers(text: str | None, count: int, what: str, *, positive: bool = False) -> list[float]:
    """`count` finite numbers separated by spaces (all > 0 if `positive`), or ConfigError."""
    parts = (text or "").split()
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    ok = len(values) == count and all(math.isfinite(v) for v in values)
    if ok and positive:
        ok = all(v > 0 for v in values)
    if not ok:
        kind = "positive" if positive else "finite"
        wanted = f"a {kind} number" if count == 1 else f"{count} {kind} numbers"
        raise ConfigError(f"{what}: expected {wanted}, got {(text or '')[:40]!r}")
    return values


def _attr_numbers(
    element: ET.Element, name: str, count: int, what: str, *, positive: bool = False
) -> None:
    if name in element.attrib:
        _numbers(element.attrib[name], count, f"{what} {name}", positive=positive)


# -- the link tree -----------------------------------------------------------


def _check_tree(links: list[str], joints: list[tuple[str, str, str]], what: str) -> None:
    """Links joined into exactly one tree: one root, one parent each, all reachable."""
    known = set(links)
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {name: [] for name in links}
    for joint, parent, child in joints:
        for role, link in (("parent", parent), ("child", child)):
            if link not in known:
                raise ConfigError(f"{what}: joint {joint!r}: {role} link {link!r} does not exist")
        if child in parent_of:
            raise ConfigError(f"{what}: link {child!r} is the child of two joints")
        parent_of[child] = parent
        children[parent].append(child)
    roots = [name for name in links if name not in parent_of]
    if not roots:
        raise ConfigError(f"{what}: no root link: the joints form a loop")
    if len(roots) != 1:
        shown = ", ".join(repr(r) for r in roots[:5]) or "none"
        raise ConfigError(
            f"{what}: {len(roots)} root links ({shown}); the links must form one tree "
            "joined by joints"
        )
    seen, todo = {roots[0]}, [roots[0]]
    while todo:
        for child in children[todo.pop()]:
            if child not in seen:
                seen.add(child)
                todo.append(child)
    if len(seen) != len(links):
        loop = sorted(known - seen)[:5]
        raise ConfigError(f"{what}: joints form a loop through {', '.join(map(repr, loop))}")


def _check_joint_type(joint: ET.Element, where: str) -> None:
    kind = joint.get("type", "")
    if kind not in JOINT_TYPES:
        raise ConfigError(f"{where}: unknown type {kind!r} (known: {', '.join(JOINT_TYPES)})")


def _unique_names(elements: Iterable[ET.Element], kind: str, what: str) -> list[str]:
    names: list[str] = []
    for element in elements:
        name = element.get("name", "")
        if not name.strip():
            raise ConfigError(f"{what}: a <{kind}> without a name")
        if not name.isprintable():
            raise ConfigError(f"{what}: a <{kind}> name with control characters: {name[:40]!r}")
        if name in names:
            raise ConfigError(f"{what}: two {kind}s named {name!r}")
        names.append(name)
    return names


# -- meshes ----------------------------------------------------------------


def _sniff_mesh(path: Path, what: str) -> None:
    """Refuse files that are plainly not the mesh their suffix says."""
    size = path.stat().st_size
    if size == 0:
        raise ConfigError(f"{what}: the mesh file is empty")
    if size > MAX_MESH_BYTES:
        raise ConfigError(f"{what}: the mesh file is larger than {MAX_MESH_BYTES >> 20} MiB")
    try:
        with open(path, "rb") as handle:
            head = handle.read(SNIFF_BYTES)
    except OSError as err:
        raise ConfigError(f"{what}: cannot read: {_reason(err)}") from None
    suffix = path.suffix.lower()
    if suffix == ".stl":
        triangles = struct.unpack_from("<I", head, 80)[0] if len(head) >= 84 else 0
        if triangles and size >= 84 + 50 * triangles:
            return
        if head.lstrip().startswith(b"solid") and b"facet" in head:
            return
        raise ConfigError(f"{what}: not an STL mesh (neither binary nor ASCII STL)")
    if suffix == ".obj":
        lines = head.splitlines()
        if any(line.startswith(b"v ") for line in lines):
            return
        raise ConfigError(f"{what}: not an OBJ mesh (no 'v' vertex lines)")
    if b"<COLLADA" not in head:
        raise ConfigError(f"{what}: not a COLLADA mesh (no <COLLADA> element)")


def _check_mesh(filename: str, model: ModelFile, schemes: tuple[str, ...], what: str) -> None:
    """A mesh named in a model: found as PyBullet would find it, and inside the model's root."""
    label = f"{what}: mesh {filename[:200]!r}"
    name = filename.strip()
    for scheme in schemes:
        if name.startswith(scheme):
            name = name[len(scheme) :]
            break
    else:
        if "://" in name:
            raise ConfigError(f"{label}: unsupported URI (use a path relative to the model file)")
    relative = _plain_relative(name, label)
    if not name.lower().endswith(MESH_SUFFIXES):
        raise ConfigError(f"{label}: PyBullet reads only {', '.join(MESH_SUFFIXES)} meshes")
    # PyBullet looks next to the model file first, then in each folder above it.
    folder = model.path.parent
    while _inside(folder, model.root):
        candidate = folder / relative
        if exists(candidate):
            _sniff_mesh(_resolved_inside(candidate, model.root, label), label)
            return
        if folder.parent == folder:
            break
        folder = folder.parent
    here = shown(str(model.path.parent))
    above = f" and the folders above it up to {shown(str(model.root))}"
    above = above if model.path.parent != model.root else ""
    raise ConfigError(f"{label}: no such file (looked in {here}{above})")


# -- URDF ------------------------------------------------------------------


def _check_origin(element: ET.Element, what: str) -> None:
    for origin in element.findall("origin"):
        _attr_numbers(origin, "xyz", 3, f"{what} origin")
        _attr_numbers(origin, "rpy", 3, f"{what} origin")


def _one_shape(geometry: ET.Element, what: str) -> ET.Element:
    """The one shape a <geometry> must hold, of a kind PyBullet reads."""
    shapes = list(geometry)
    if len(shapes) != 1:
        raise ConfigError(f"{what}: <geometry> needs exactly one shape, got {len(shapes)}")
    if shapes[0].tag not in SHAPES:
        raise ConfigError(f"{what}: unknown shape <{shapes[0].tag}> (known: {', '.join(SHAPES)})")
    return shapes[0]


def _urdf_geometry(holder: ET.Element, what: str) -> str | None:
    """Check one <visual>/<collision>; the mesh file name it uses, if any."""
    _check_origin(holder, what)
    geometries = holder.findall("geometry")
    if len(geometries) != 1:
        raise ConfigError(f"{what}: needs one <geometry>, got {len(geometries)}")
    shape = _one_shape(geometries[0], what)
    where = f"{what} <{shape.tag}>"
    for name, count in _SIZES.get(shape.tag, ()):
        _numbers(shape.get(name), count, f"{where} {name}", positive=True)
    if shape.tag == "plane":
        _attr_numbers(shape, "normal", 3, where)
    elif shape.tag == "mesh":
        _attr_numbers(shape, "scale", 3, where)
        filename = shape.get("filename", "")
        if not filename.strip():
            raise ConfigError(f"{where}: no filename")
        return filename
    return None


def _check_urdf(root: ET.Element, model: ModelFile, what: str) -> ModelParts:
    if root.tag != "robot":
        raise ConfigError(f"{what}: not a URDF: the root element is <{root.tag}>, not <robot>")
    links = root.findall("link")
    if not links:
        raise ConfigError(f"{what}: the robot has no <link>")
    names = _unique_names(links, "link", what)
    meshes: list[tuple[str, str]] = []
    for link, name in zip(links, names, strict=True):
        where = f"{what}: link {name!r}"
        for inertial in link.findall("inertial"):
            _check_origin(inertial, where)
            for mass in inertial.findall("mass"):
                _numbers(mass.get("value"), 1, f"{where} mass")
            for inertia in inertial.findall("inertia"):
                for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                    _attr_numbers(inertia, key, 1, f"{where} inertia")
        for kind in ("visual", "collision"):
            for holder in link.findall(kind):
                mesh = _urdf_geometry(holder, f"{where} {kind}")
                if mesh is not None:
                    meshes.append((mesh, where))
    joints = root.findall("joint")
    joint_names = _unique_names(joints, "joint", what)
    tree: list[tuple[str, str, str]] = []
    for joint, name in zip(joints, joint_names, strict=True):
        where = f"{what}: joint {name!r}"
        _check_joint_type(joint, where)
        ends = []
        for role in ("parent", "child"):
            element = joint.find(role)
            link_name = element.get("link", "") if element is not None else ""
            if not link_name:
                raise ConfigError(f"{where}: no <{role} link=...>")
            ends.append(link_name)
        tree.append((name, ends[0], ends[1]))
        _check_origin(joint, where)
        for axis in joint.findall("axis"):
            if "xyz" in axis.attrib:
                xyz = _numbers(axis.get("xyz"), 3, f"{where} axis xyz")
                if not any(xyz):
                    raise ConfigError(f"{where}: axis xyz is the zero vector")
        for limit in joint.findall("limit"):
            for key in ("lower", "upper", "effort", "velocity"):
                _attr_numbers(limit, key, 1, f"{where} limit")
    _check_tree(names, tree, what)
    for filename, where in meshes:
        _check_mesh(filename, model, ("package://",), where)
    kinds = [joint.get("type", "") for joint in joints]
    return ModelParts(tuple(names), tuple(zip(joint_names, kinds, strict=True)))


# -- SDF -------------------------------------------------------------------


def _text_numbers(parent: ET.Element, tag: str, count: int, what: str, positive: bool) -> None:
    element = parent.find(tag)
    if element is None:
        raise ConfigError(f"{what}: no <{tag}>")
    _numbers(element.text, count, f"{what} <{tag}>", positive=positive)


def _sdf_poses(element: ET.Element, what: str) -> None:
    for pose in element.iter("pose"):
        if (pose.text or "").strip():
            _numbers(pose.text, 6, f"{what} <pose>")


def _sdf_geometry(holder: ET.Element, what: str) -> str | None:
    geometry = holder.find("geometry")
    if geometry is None:
        raise ConfigError(f"{what}: no <geometry>")
    shape = _one_shape(geometry, what)
    where = f"{what} <{shape.tag}>"
    for name, count in _SIZES.get(shape.tag, ()):
        _text_numbers(shape, name, count, where, True)
    if shape.tag == "plane":
        for tag, count in (("normal", 3), ("size", 2)):
            if shape.find(tag) is not None:
                _text_numbers(shape, tag, count, where, tag == "size")
    elif shape.tag == "mesh":
        if shape.find("scale") is not None:
            _text_numbers(shape, "scale", 3, where, False)
        uri = shape.findtext("uri", "").strip()
        if not uri:
            raise ConfigError(f"{where}: no <uri>")
        return uri
    return None


def _check_sdf(root: ET.Element, model: ModelFile, what: str) -> None:
    if root.tag != "sdf":
        raise ConfigError(f"{what}: not an SDF file: the root element is <{root.tag}>, not <sdf>")
    if root.find(".//include") is not None:
        raise ConfigError(f"{what}: <include> is not supported by PyBullet; put the model inline")
    models = root.findall("model") + root.findall("world/model")
    if not models:
        raise ConfigError(f"{what}: no <model> (directly or in a <world>)")
    _sdf_poses(root, what)
    meshes: list[tuple[str, str]] = []
    for element in models:
        where = f"{what}: model {element.get('name', '')!r}"
        if element.find("model") is not None:
            raise ConfigError(f"{where}: nested models are not supported by PyBullet")
        links = element.findall("link")
        if not links:
            raise ConfigError(f"{where}: has no <link>")
        names = _unique_names(links, "link", where)
        for link, name in zip(links, names, strict=True):
            for kind in ("visual", "collision"):
                for holder in link.findall(kind):
                    mesh = _sdf_geometry(holder, f"{where} link {name!r} {kind}")
                    if mesh is not None:
                        meshes.append((mesh, f"{where} link {name!r}"))
        joints = element.findall("joint")
        joint_names = _unique_names(joints, "joint", where)
        tree = [
            (name, joint.findtext("parent", "").strip(), joint.findtext("child", "").strip())
            for joint, name in zip(joints, joint_names, strict=True)
        ]
        for joint, (name, parent, child) in zip(joints, tree, strict=True):
            _check_joint_type(joint, f"{where}: joint {name!r}")
            if not parent or not child:
                raise ConfigError(f"{where}: joint {name!r} needs <parent> and <child>")
        _check_tree(names, tree, where)
    for uri, where in meshes:
        _check_mesh(uri, model, ("model://", "package://"), where)


def check_model_file(model: ModelFile, *, what: str = "") -> ModelParts:
    """Refuse a URDF/SDF file PyBullet would choke, crash or print garbage on.

    `what` prefixes the messages (e.g. ``cannot load 'table.urdf'``). A
    URDF's link and joint names come back, for checks that name them.
    """
    label = what or str(model.path)
    root = parse_xml(model.path, label)
    if model.path.suffix == ".sdf":
        _check_sdf(root, model, label)
        return ModelParts()
    return _check_urdf(root, model, label)
