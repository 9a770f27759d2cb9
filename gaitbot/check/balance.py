"""Balance of a trajectory: the whole robot's centre of mass and its ZMP against the support polygon.

A trajectory inside every joint limit can still tip the robot over. From the trajectory alone (joint
angles, root, torso attitude) and the robot's mass model (``config.body``: every link's mass and centre
of mass), frame by frame:

* every link's centre of mass in the world (the 6-joint leg kinematics, gaitbot.gait.kinematics6);
* the ZMP of those point masses on flat ground at z = 0, accelerations by central second differences
  at the frame times: ``p = sum m (x (z'' + g) - z x'') / sum m (z'' + g)`` (Kajita et al. 2003, eq. 2,
  the links' rotational inertia left out);
* the support polygon: the convex hull of the sole corners within ``CONTACT_TOL_M`` of the ground.

A ZMP outside the polygon is a ``balance`` violation: how far outside (m), when, and which way the
robot would tip. Robots that walk on a boom (``[robot] boom = true``, or ``--boom``) are not checked:
a boom holds them up. docs/checking.md says what is reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.joints import LEG_JOINTS, SIDES
from gaitbot.gait.kinematics6 import sole_corners
from gaitbot.gait.mass import GRAVITY_M_S2, MassModel
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig

CONTACT_TOL_M = 1e-3
"""A sole corner this close to the ground (or below it) bears weight; one further below it is an error of the root."""


@dataclass(frozen=True, eq=False)
class BalanceTrace:
    """Frame by frame: the CoM (N, 3) and ZMP (N, 2) in the world, the support polygon of each frame
    (a list of (K, 2) counter-clockwise hulls, empty when no sole touches), and the ZMP's signed distance
    to its polygon's edge (N,) in metres: positive inside, negative outside."""

    t_s: np.ndarray
    com_m: np.ndarray
    zmp_m: np.ndarray
    support: list
    margin_m: np.ndarray
    soles: dict  # side -> (N, 4, 3) sole corners in the world


def rotation_rpy(rpy_rad: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotations Rz(yaw) Ry(pitch) Rx(roll) for (N, 3) roll, pitch, yaw."""
    r, p, y = rpy_rad[:, 0], rpy_rad[:, 1], rpy_rad[:, 2]
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.stack([np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
                     np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
                     np.stack([-sp, cp * sr, cp * cr], -1)], axis=-2)


def leg_angles_rad(config: RobotConfig, angles_deg_all: np.ndarray) -> np.ndarray:
    """(N, 12) angles of the 12 leg joints (LEG_JOINTS order) from the robot's (N, n_joints) degrees;
    joints the robot lacks are straight (0)."""
    out = np.zeros((len(angles_deg_all), len(LEG_JOINTS)))
    names = config.joint_names
    for i, name in enumerate(LEG_JOINTS):
        if name in names:
            out[:, i] = np.radians(angles_deg_all[:, names.index(name)])
    return out


def _second_difference(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """x'' at every frame (non-uniform central differences; the ends copy their neighbours)."""
    acc = np.zeros_like(x)
    if len(t) >= 3:
        dt = np.diff(t)[(slice(None),) + (None,) * (x.ndim - 1)]
        v = np.diff(x, axis=0) / dt
        acc[1:-1] = 2.0 * np.diff(v, axis=0) / (dt[1:] + dt[:-1])
        acc[0], acc[-1] = acc[1], acc[-2]
    return acc


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise, no repeated end) of (K, 2) points: Andrew's monotone chain."""
    pts = sorted(set(map(tuple, np.round(points, 12))))
    if len(pts) <= 2:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(reversed(pts))
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def signed_distance(point: np.ndarray, hull: np.ndarray) -> float:
    """Distance from ``point`` to the hull's boundary: positive inside, negative outside (-inf: no hull)."""
    if len(hull) == 0:
        return -math.inf
    if len(hull) == 1:
        return -float(np.linalg.norm(point - hull[0]))
    a, b = hull, np.roll(hull, -1, axis=0)
    if len(hull) == 2:
        a, b = hull[:1], hull[1:]
    ab, ap = b - a, point - a
    s = np.clip(np.einsum("ij,ij->i", ap, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    nearest = float(np.min(np.linalg.norm(a + s[:, None] * ab - point, axis=1)))
    if len(hull) == 2:
        return -nearest
    inside = np.all(ab[:, 0] * ap[:, 1] - ab[:, 1] * ap[:, 0] >= 0.0)
    return nearest if inside else -nearest


def balance_trace(config: RobotConfig, trajectory: Trajectory, angles_deg_all: np.ndarray) -> BalanceTrace:
    """The trace of ``trajectory`` on ``config`` (``angles_deg_all``: the robot's (N, n_joints) angles)."""
    body = config.body
    model = MassModel.of(body)
    q = leg_angles_rad(config, angles_deg_all)
    n = len(q)
    rotation = (rotation_rpy(trajectory.torso_rpy_rad) if trajectory.torso_rpy_rad is not None
                else np.broadcast_to(np.eye(3), (n, 3, 3)))
    root = trajectory.root_m

    def world(points_in_root: np.ndarray) -> np.ndarray:  # (N, K, 3)
        return root[:, None, :] + np.einsum("nij,nkj->nki", rotation, points_in_root)

    masses = [model.torso_kg]
    points = [np.broadcast_to(model.torso_com_m, (n, 1, 3))]
    soles = {}
    g = body.geometry
    for i, side in enumerate(SIDES):
        legs = q[:, 6 * i:6 * i + 6]
        masses.extend(model.leg_kg)
        points.append(model.leg_link_coms(side, legs))
        soles[side] = world(sole_corners(g, side, legs))
    m = np.array(masses)
    coms = world(np.concatenate(points, axis=1))  # (N, 13, 3)
    com = np.einsum("k,nkj->nj", m, coms) / m.sum()
    acc = _second_difference(trajectory.t_s, coms)
    weight = m * (acc[:, :, 2] + GRAVITY_M_S2)  # (N, 13)
    denominator = weight.sum(axis=1)
    zmp = np.stack([(np.einsum("nk,nk->n", weight, coms[:, :, j])
                     - np.einsum("k,nk,nk->n", m, coms[:, :, 2], acc[:, :, j])) / denominator for j in (0, 1)], -1)
    support, margin = [], np.empty(n)
    for k in range(n):
        touching = [soles[side][k][soles[side][k][:, 2] <= CONTACT_TOL_M, :2] for side in SIDES]
        hull = _hull(np.concatenate(touching)) if any(len(c) for c in touching) else np.zeros((0, 2))
        support.append(hull)
        margin[k] = signed_distance(zmp[k], hull)
    return BalanceTrace(trajectory.t_s, com, zmp, support, margin, soles)


def tipping_direction(zmp: np.ndarray, hull: np.ndarray) -> str:
    """Which way a ZMP outside the hull tips the robot: forwards, backwards or sideways (left/right)."""
    if len(hull) == 0:
        return "with no foot on the ground"
    centre = hull.mean(axis=0)
    dx, dy = zmp - centre
    if abs(dx) >= abs(dy):
        return "forwards" if dx > 0 else "backwards"
    return "sideways, to the left" if dy > 0 else "sideways, to the right"
