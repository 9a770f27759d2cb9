"""A URDF file as a description tree (gaitbot.robot.description.tree), every problem one line.

URDF (ROS's format, https://wiki.ros.org/urdf/XML): links with an optional inertial (origin, mass, inertia
about the centre of mass in the origin's frame) and collision shapes; joints joining a parent link to a
child, the child's frame at the joint's origin, revolute and continuous joints turning about ``axis``
(joint frame, default x), the others (fixed, and prismatic or floating, which a leg cannot use) rigid at 0.
Meshes are never read: only boxes matter (the feet). Read with the standard library's XML parser from a
size-capped file; documents declaring entities are refused (no expansion bombs).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from gaitbot.fields import read_user_file
from gaitbot.robot.description.tree import (MAX_BODIES, MAX_DESCRIPTION_BYTES, MAX_MAGNITUDE, Body, Box,
                                            DescriptionError, Hinge, Tree, checked_inertial, ordered, rpy_matrix)

HINGE_TYPES = ("revolute", "continuous")


def read_xml(path: Path) -> ET.Element:
    """The root element of a description file: size-capped, no entity declarations, one line on any problem."""
    try:
        data = read_user_file(path, MAX_DESCRIPTION_BYTES)
    except OSError as exc:
        raise DescriptionError(path, "file", f"cannot read ({exc.strerror or exc})") from None
    if b"<!ENTITY" in data:
        raise DescriptionError(path, "file", "declares XML entities, which a robot description does not need "
                                             "(refused: they can expand without bound)")
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        raise DescriptionError(path, "file", f"not XML ({exc})") from None
    except (RecursionError, MemoryError, ValueError) as exc:
        raise DescriptionError(path, "file", f"not readable as XML ({type(exc).__name__})") from None


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, reason: str) -> DescriptionError:
        return DescriptionError(self.path, where, reason)

    def numbers(self, element: ET.Element | None, key: str, where: str, count: int, default=None) -> np.ndarray:
        text = None if element is None else element.get(key)
        if text is None:
            if default is None:
                raise self.fail(where, f"missing {key}=\"...\" ({count} number{'s' if count > 1 else ''})")
            return np.array(default, dtype=float)
        try:
            values = np.array([float(v) for v in text.split()], dtype=float)
        except ValueError:
            raise self.fail(where, f"{key}={text[:40]!r} is not {count} number{'s' if count > 1 else ''}") from None
        if len(values) != count or not np.all(np.isfinite(values)) or np.abs(values).max() > MAX_MAGNITUDE:
            raise self.fail(where, f"{key}={text[:40]!r}: expected {count} finite number{'s' if count > 1 else ''} "
                                   f"within +-{MAX_MAGNITUDE:g}")
        return values

    def origin(self, element: ET.Element, where: str) -> tuple[np.ndarray, np.ndarray]:
        o = element.find("origin")
        xyz = self.numbers(o, "xyz", f"{where}.origin", 3, (0, 0, 0))
        rpy = self.numbers(o, "rpy", f"{where}.origin", 3, (0, 0, 0))
        return xyz, rpy_matrix(*rpy)

    def name(self, element: ET.Element, what: str) -> str:
        name = element.get("name")
        if not name:
            raise self.fail(what, "an element without a name")
        return name[:200]

    def inertial(self, link: ET.Element, where: str):
        element = link.find("inertial")
        if element is None:
            return None
        xyz, rotation = self.origin(element, f"{where}.inertial")
        mass = float(self.numbers(element.find("mass"), "value", f"{where}.inertial.mass", 1)[0])
        i = element.find("inertia")
        if i is None:
            raise self.fail(f"{where}.inertial", "missing <inertia>")
        ixx, ixy, ixz, iyy, iyz, izz = (float(self.numbers(i, k, f"{where}.inertial.inertia", 1)[0])
                                        for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        return checked_inertial(str(self.path), where, mass, xyz, rotation @ inertia @ rotation.T)

    def boxes(self, link: ET.Element, where: str) -> tuple[Box, ...]:
        out = []
        for collision in link.findall("collision"):
            box = collision.find("geometry/box")
            if box is not None:
                xyz, rotation = self.origin(collision, f"{where}.collision")
                size = self.numbers(box, "size", f"{where}.collision.box", 3)
                out.append(Box(xyz, rotation, np.abs(size) / 2))
        return tuple(out)

    def joint(self, joint: ET.Element) -> tuple[str, str, np.ndarray, np.ndarray, Hinge | None]:
        name = self.name(joint, "joint")
        where = f"joint {name}"
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None or not parent.get("link") or not child.get("link"):
            raise self.fail(where, "needs <parent link=...> and <child link=...>")
        xyz, rotation = self.origin(joint, where)
        hinge = None
        if joint.get("type") in HINGE_TYPES:
            axis = self.numbers(joint.find("axis"), "xyz", f"{where}.axis", 3, (1, 0, 0))
            norm = float(np.linalg.norm(axis))
            if not norm > 1e-9:
                raise self.fail(f"{where}.axis", "a zero axis")
            limit, bounds = joint.find("limit"), None
            if joint.get("type") == "revolute" and limit is not None:
                lo = float(self.numbers(limit, "lower", f"{where}.limit", 1, (0.0,))[0])
                hi = float(self.numbers(limit, "upper", f"{where}.limit", 1, (0.0,))[0])
                bounds = (lo, hi) if lo < hi and hi - lo < 4 * math.pi else None
            hinge = Hinge(name, axis / norm, np.zeros(3), bounds)
        elif joint.get("type") is None:
            raise self.fail(where, "missing type=\"...\" (revolute, continuous, fixed ...)")
        return parent.get("link"), child.get("link"), xyz, rotation, hinge


def read_urdf(path: str | Path) -> Tree:
    """The URDF file at ``path`` as a description tree; DescriptionError (one line) when it cannot be one."""
    path = Path(path)
    root = read_xml(path)
    if root.tag != "robot":
        raise DescriptionError(path, "file", f"the root element is <{root.tag[:40]}>, not a URDF's <robot>")
    reader = _Reader(path)
    links, joints = root.findall("link"), root.findall("joint")
    if len(links) > MAX_BODIES or len(joints) > MAX_BODIES:
        raise DescriptionError(path, "file", f"more than {MAX_BODIES} links or joints: not a robot description")
    if not links:
        raise DescriptionError(path, "file", "no <link> elements")
    by_child: dict[str, tuple] = {}
    joint_names = set()
    for element in joints:
        parent, child, xyz, rotation, hinge = reader.joint(element)
        name = element.get("name")
        if name in joint_names:
            raise DescriptionError(path, f"joint {name}", "two joints have this name")
        if child in by_child:
            raise DescriptionError(path, f"link {child}", f"is the child of two joints ({by_child[child][0]}, {name}): "
                                                          f"a robot description must be a tree")
        joint_names.add(name)
        by_child[child] = (name, parent, xyz, rotation, hinge)
    link_names = {reader.name(link, "link") for link in links}
    for name, (joint, parent, *_rest) in by_child.items():
        for end in (name, parent):
            if end not in link_names:
                raise DescriptionError(path, f"joint {joint}", f"names link {end!r}, which does not exist")
    bodies = []
    for link in links:
        name = reader.name(link, "link")
        joint = by_child.get(name)
        parent, xyz, rotation, hinge = (joint[1], joint[2], joint[3], joint[4]) if joint else (None, np.zeros(3),
                                                                                              np.eye(3), None)
        bodies.append(Body(name, parent, xyz, rotation, hinge, reader.inertial(link, f"link {name}"),
                           reader.boxes(link, f"link {name}")))
    ordered_bodies, root_name = ordered(str(path), bodies)
    return Tree(str(path), root.get("name") or path.stem, ordered_bodies, root_name)
