"""The robot's link frames from its joint angles, as the URDF export of it names and places them (for /tf).

Naming (docs/live-view.md; the same as ``gaitbot robot export --urdf`` and the simulated robot's bodies):
the pelvis is ``base_link``; per leg, from the pelvis down, the links ``hip_yaw_<side>``, ``hip_roll_<side>``,
``thigh_<side>``, ``shank_<side>``, ``ankle_<side>`` and ``foot_<side>`` (gaitbot.gait.body.LEG_LINKS), each
turned by the joint of the same rank (``hip_yaw_left`` ... ``ankle_roll_left``); the fixed frame is ``odom``
(REP-105: the walk's world frame as dead reckoning knows it, the floor at z = 0).

Each link frame sits at its joint point with the root's axes at the zero pose, as gaitbot.gait.kinematics6
defines the leg: hip_yaw at the hip point, hip_roll and thigh on it, shank ``thigh_m`` below, ankle
``shank_m`` below that, foot on it; axes in gaitbot's sign conventions (gaitbot.gait.joints). A joint's
transform is then its fixed offset and a rotation about its axis by its angle, which is what a URDF's
revolute joint with ``rpy="0 0 0"`` and that axis gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.body import LEG_LINKS, SIDE_SIGN, BodyGeometry
from gaitbot.gait.joints import LEG_JOINT_KINDS, LEG_JOINTS, SIDES

WORLD_FRAME = "odom"
BASE_LINK = "base_link"


_LINK_OF_KIND = dict(zip(LEG_JOINT_KINDS, LEG_LINKS))


def link_name(joint: str) -> str:
    """The link a joint turns (the convention of the module docstring): ``knee_pitch_left`` -> ``shank_left``."""
    kind, _, side = joint.rpartition("_")
    return f"{_LINK_OF_KIND[kind]}_{side}"


def joint_axis(kind: str, side: str) -> tuple[float, float, float]:
    """A leg joint's axis in its parent's frame (= the root frame at the zero pose), positive angle in the
    sense of gaitbot.gait.joints: yaw toe out, roll abduction, pitch flexion (the knee bends forward)."""
    s = SIDE_SIGN[side]
    return {"hip_yaw": (0.0, 0.0, s), "hip_roll": (s, 0.0, 0.0), "hip_pitch": (0.0, -1.0, 0.0),
            "knee_pitch": (0.0, 1.0, 0.0), "ankle_pitch": (0.0, -1.0, 0.0), "ankle_roll": (s, 0.0, 0.0)}[kind]


@dataclass(frozen=True)
class JointFrame:
    """One revolute joint of the tree: parent and child link, offset (m) in the parent frame, unit axis."""

    joint: str
    parent: str
    child: str
    offset_m: tuple[float, float, float]
    axis: tuple[float, float, float]


def joint_frames(geometry: BodyGeometry) -> tuple[JointFrame, ...]:
    """The 12 leg joints (LEG_JOINTS order) as a URDF tree under ``base_link``."""
    frames = []
    for side in SIDES:
        parent = BASE_LINK
        offsets = {"hip_yaw": tuple(float(v) for v in geometry.hip_in_root(side)), "hip_roll": (0.0, 0.0, 0.0),
                   "hip_pitch": (0.0, 0.0, 0.0), "knee_pitch": (0.0, 0.0, -geometry.thigh_m),
                   "ankle_pitch": (0.0, 0.0, -geometry.shank_m), "ankle_roll": (0.0, 0.0, 0.0)}
        for kind in LEG_JOINT_KINDS:
            joint = f"{kind}_{side}"
            frames.append(JointFrame(joint, parent, link_name(joint), offsets[kind], joint_axis(kind, side)))
            parent = link_name(joint)
    return tuple(frames)


def quaternion_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of Rz(yaw) Ry(pitch) Rx(roll), the REP-103 fixed-axis roll, pitch, yaw."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


@dataclass(frozen=True)
class Transform:
    """A parent -> child transform: translation (m) and rotation as a unit quaternion (x, y, z, w)."""

    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation_xyzw: tuple[float, float, float, float]


class LinkTransforms:
    """The transforms of one robot's tree for any joint angles (built once; per frame a few float operations)."""

    def __init__(self, geometry: BodyGeometry) -> None:
        self.frames = joint_frames(geometry)

    def transforms(self, joints, angles_rad, root_m, root_rpy_rad=(0.0, 0.0, 0.0)) -> list[Transform]:
        """odom -> base_link from the root pose, then every leg joint (a joint missing from ``joints`` is at 0,
        as a held joint is)."""
        angle = dict(zip(joints, (float(a) for a in angles_rad)))
        out = [Transform(WORLD_FRAME, BASE_LINK, tuple(float(v) for v in root_m), quaternion_rpy(*map(float, root_rpy_rad)))]
        for f in self.frames:
            half = angle.get(f.joint, 0.0) / 2.0
            s = math.sin(half)
            out.append(Transform(f.parent, f.child, f.offset_m, (f.axis[0] * s, f.axis[1] * s, f.axis[2] * s, math.cos(half))))
        return out


def link_names() -> tuple[str, ...]:
    """Every link of the tree, base first."""
    return (BASE_LINK,) + tuple(link_name(j) for j in LEG_JOINTS)
