"""The robot's frames for /tf and /tf_static, from the exported robot's joint table (one table for both).

The frames are those ``gaitbot robot export --urdf`` writes (gaitbot.robot.description.frames, names in
docs/robot-description.md): a walking joint turns its child link about its axis, and goes to /tf each frame;
every fixed joint (a held joint at its hold angle, the frames other tools look for: ``torso``, ``trunk``,
``l_sole``/``r_sole``, ``left_foot``/``right_foot``, ``left_hip_yaw``/``right_hip_yaw``) goes to /tf_static.
The fixed frame of the walk is ``odom`` (REP-105: the walk's world as dead reckoning knows it, the floor at
z = 0), its child the root ``base_link``. A tool that draws the URDF then places every link as gaitbot's
kinematics do (tests/view/test_link_frames.py checks it against gaitbot.gait.kinematics6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.frames import ROOT_LINK, JointFrame, joint_frames

WORLD_FRAME = "odom"
BASE_LINK = ROOT_LINK


def quaternion_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of Rz(yaw) Ry(pitch) Rx(roll), the REP-103 fixed-axis roll, pitch, yaw."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def rotation_xyzw(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """The unit quaternion of a rotation matrix (Shepperd's method: the largest diagonal term first)."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        return ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
    q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
    q[i], q[j], q[k] = s / 4, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
    return tuple(float(v) for v in q)


@dataclass(frozen=True)
class Transform:
    """A parent -> child transform: translation (m) and rotation as a unit quaternion (x, y, z, w)."""

    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation_xyzw: tuple[float, float, float, float]


def _fixed(row: JointFrame) -> Transform:
    translation, rotation = row.transform()
    return Transform(row.parent, row.child, tuple(float(v) for v in translation), rotation_xyzw(rotation))


class LinkTransforms:
    """The transforms of one robot's tree for any joint angles (built once; per frame a few float operations)."""

    def __init__(self, config: RobotConfig) -> None:
        rows = joint_frames(config)
        self.moving = tuple(row for row in rows if row.moving)
        self.static = tuple(_fixed(row) for row in rows if not row.moving)
        self._offsets = [tuple(float(v) for v in row.origin_m) for row in self.moving]
        self._axes = [tuple(float(v) for v in row.axis) for row in self.moving]

    def transforms(self, joints, angles_rad, root_m, root_rpy_rad=(0.0, 0.0, 0.0)) -> list[Transform]:
        """odom -> base_link from the root pose, then every walking joint (one missing from ``joints``: at 0)."""
        angle = dict(zip(joints, (float(a) for a in angles_rad)))
        out = [Transform(WORLD_FRAME, BASE_LINK, tuple(float(v) for v in root_m), quaternion_rpy(*map(float, root_rpy_rad)))]
        for row, offset, (ax, ay, az) in zip(self.moving, self._offsets, self._axes):
            half = angle.get(row.name, 0.0) / 2.0
            s = math.sin(half)
            out.append(Transform(row.parent, row.child, offset, (ax * s, ay * s, az * s, math.cos(half))))
        return out

    def link_of(self, joint: str) -> str:
        """The link a walking joint turns: ``knee_pitch_left`` -> ``shank_left``."""
        return next(row.child for row in self.moving if row.name == joint)
