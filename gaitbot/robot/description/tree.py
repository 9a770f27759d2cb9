"""A robot description as a tree of rigid bodies: what the URDF and MJCF readers give the importer.

Why a format of our own: a URDF (links and joints) and an MJCF (nested bodies, compiled by MuJoCo in the sim
room) say the same things in different ways; the importer (gaitbot.robot.description.importer) reads one
tree. A body has its frame in its parent's (position, rotation), at most one hinge joint that turns it
(axis and anchor in its own frame, the range if the description gives one), its mass, centre of mass and
inertia about it in its own frame (None: a massless frame), and its box collision shapes (the feet).
The zero pose is every hinge at 0. Lengths in metres, angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gaitbot.fields import FieldError
from gaitbot.gait.body import LinkInertial

#: The most bodies a description may hold (a humanoid has about 30; beyond this it is not a robot file).
MAX_BODIES = 2000
#: The largest description file read (bytes): the shipped and Menagerie files are ~10-100 KB without meshes.
MAX_DESCRIPTION_BYTES = 8 * 2**20
#: No number of a robot description means anything beyond this (metres, kilograms, kg m^2, radians).
MAX_MAGNITUDE = 1e6


class DescriptionError(FieldError):
    """A robot description (URDF, MJCF) gaitbot cannot use: one line, ``<file>: <where>: <what is wrong>``."""


@dataclass(frozen=True, eq=False)
class Box:
    """A box collision shape: centre and rotation in its body's frame, half sizes (m)."""

    centre_m: np.ndarray
    rotation: np.ndarray
    half_m: np.ndarray


@dataclass(frozen=True, eq=False)
class Hinge:
    """A revolute joint: it turns its body about ``axis`` (unit, body frame) through ``anchor_m`` (body frame)."""

    name: str
    axis: np.ndarray
    anchor_m: np.ndarray
    range_rad: tuple[float, float] | None = None


@dataclass(frozen=True, eq=False)
class Body:
    name: str
    parent: str | None
    position_m: np.ndarray
    rotation: np.ndarray
    hinge: Hinge | None = None
    inertial: LinkInertial | None = None
    boxes: tuple[Box, ...] = ()


@dataclass(eq=False)
class Tree:
    """The bodies of one description, parents before children; ``root`` is the free-floating body (the pelvis)."""

    path: str
    name: str
    bodies: dict[str, Body]
    root: str
    children: dict[str, list[str]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for body in self.bodies.values():
            if body.parent is not None:
                self.children.setdefault(body.parent, []).append(body.name)

    def fail(self, where: str, reason: str) -> DescriptionError:
        return DescriptionError(self.path, where, reason)

    @property
    def hinges(self) -> dict[str, Body]:
        """Hinge joint name -> the body it turns."""
        return {b.hinge.name: b for b in self.bodies.values() if b.hinge is not None}

    def hinge_ancestors(self, body: str) -> list[str]:
        """The hinge joints between the root and ``body`` (``body``'s own included), root first."""
        out = []
        name: str | None = body
        while name is not None and name != self.root:
            b = self.bodies[name]
            if b.hinge is not None:
                out.append(b.hinge.name)
            name = b.parent
        return out[::-1]

    def subtree(self, body: str) -> list[str]:
        out, stack = [], [body]
        while stack:
            name = stack.pop()
            out.append(name)
            stack.extend(self.children.get(name, []))
        return out

    def frames(self, angles_rad: dict[str, float] | None = None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Every body's (rotation, origin) in the root's frame, hinges at ``angles_rad`` (missing: 0)."""
        angles_rad = angles_rad or {}
        out = {self.root: (np.eye(3), np.zeros(3))}
        for name in self.bodies:  # parents come first
            if name == self.root or self.bodies[name].parent not in out:
                continue
            b = self.bodies[name]
            r_parent, p_parent = out[b.parent]
            rotation, origin = r_parent @ b.rotation, p_parent + r_parent @ b.position_m
            if b.hinge is not None and angles_rad.get(b.hinge.name, 0.0):
                turn = axis_angle(b.hinge.axis, angles_rad[b.hinge.name])
                origin = origin + rotation @ (b.hinge.anchor_m - turn @ b.hinge.anchor_m)
                rotation = rotation @ turn
            out[name] = (rotation, origin)
        return out


def ordered(path: str, bodies: list[Body]) -> tuple[dict[str, Body], str]:
    """Bodies sorted parents first, and the root; DescriptionError for a repeated name, a parent that does not
    exist, a cycle, several roots or too many bodies."""
    if len(bodies) > MAX_BODIES:
        raise DescriptionError(path, "file", f"{len(bodies)} bodies, more than a robot has (at most {MAX_BODIES})")
    by_name: dict[str, Body] = {}
    for b in bodies:
        if b.name in by_name:
            raise DescriptionError(path, b.name, "two bodies (links) have this name")
        by_name[b.name] = b
    roots = [b.name for b in bodies if b.parent is None]
    for b in bodies:
        if b.parent is not None and b.parent not in by_name:
            raise DescriptionError(path, b.name, f"its parent {b.parent!r} does not exist")
        numbers = np.concatenate([b.position_m, np.ravel(b.rotation)])
        if not np.all(np.isfinite(numbers)) or np.abs(numbers).max() > MAX_MAGNITUDE:
            raise DescriptionError(path, b.name, f"its place is not finite or beyond {MAX_MAGNITUDE:g} m")
    if not roots:
        raise DescriptionError(path, "file", "every link has a parent: the links form a cycle, a robot is a tree")
    if len(roots) > 1:
        raise DescriptionError(path, "file", f"{len(roots)} links have no parent joint ({', '.join(roots[:5])}): a "
                                             f"missing joint? a robot description is one tree")
    children: dict[str, list[str]] = {}
    for b in bodies:
        if b.parent is not None:
            children.setdefault(b.parent, []).append(b.name)
    out: dict[str, Body] = {}
    stack = [roots[0]]
    while stack:
        name = stack.pop()
        out[name] = by_name[name]
        stack.extend(reversed(children.get(name, [])))
    if len(out) != len(by_name):
        cycle = sorted(set(by_name) - set(out))
        raise DescriptionError(path, cycle[0], f"is in a cycle of links ({', '.join(cycle[:6])}): "
                                               f"a robot description must be a tree")
    return out, roots[0]


def checked_inertial(path: str, where: str, mass_kg: float, com_m, inertia) -> LinkInertial:
    """A body's inertial, refused unless its mass is positive and its numbers finite."""
    values = np.concatenate([[mass_kg], np.ravel(com_m), np.ravel(inertia)])
    if not np.all(np.isfinite(values)) or np.abs(values).max() > MAX_MAGNITUDE:
        raise DescriptionError(path, where, f"inertial: a number is not finite or beyond {MAX_MAGNITUDE:g}")
    if not mass_kg > 0:
        raise DescriptionError(path, where, f"mass {mass_kg:g} kg: a body's mass must be positive "
                                            f"(leave the inertial out for a massless frame)")
    inertia = np.asarray(inertia, dtype=float)
    return LinkInertial(float(mass_kg), np.asarray(com_m, dtype=float), (inertia + inertia.T) / 2)


def axis_angle(axis, angle_rad: float) -> np.ndarray:
    """The rotation by ``angle_rad`` about the unit ``axis`` (Rodrigues)."""
    x, y, z = axis
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]], dtype=float)
    return np.eye(3) + np.sin(angle_rad) * k + (1 - np.cos(angle_rad)) * k @ k


def quaternion_matrix(w: float, x: float, y: float, z: float) -> np.ndarray:
    """The rotation of a quaternion (w first, as MJCF writes it), normalised."""
    n = np.sqrt(w * w + x * x + y * y + z * z)
    if not n > 0:
        raise ValueError("a zero quaternion")
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's rpy: fixed-axis rotations about x, then y, then z (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    return axis_angle((0, 0, 1), yaw) @ axis_angle((0, 1, 0), pitch) @ axis_angle((1, 0, 0), roll)


def matrix_rpy(r: np.ndarray) -> tuple[float, float, float]:
    """The URDF rpy of a rotation matrix (inverse of rpy_matrix away from pitch +-90 deg)."""
    pitch = float(np.arcsin(np.clip(-r[2, 0], -1.0, 1.0)))
    return float(np.arctan2(r[2, 1], r[2, 2])), pitch, float(np.arctan2(r[1, 0], r[0, 0]))


def matrix_quaternion(r: np.ndarray) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z) of a rotation matrix (the inverse of quaternion_matrix, w >= 0)."""
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = (0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    else:
        i = int(np.argmax([r[0, 0], r[1, 1], r[2, 2]]))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        v = [0.0, 0.0, 0.0]
        v[i], v[j], v[k] = 0.25 * s, (r[j, i] + r[i, j]) / s, (r[k, i] + r[i, k]) / s
        q = ((r[k, j] - r[j, k]) / s, *v)
    q = np.array(q, dtype=float)
    q = q if q[0] >= 0 else -q
    return tuple(float(v) for v in q / np.linalg.norm(q))  # type: ignore[return-value]
