"""The exported robot's frames as a table of joints: written once, for the URDF and for live transforms.

Each row joins a parent frame to a child frame: the child's origin in the parent's frame at the zero pose,
the joint's axis, and whether it turns (a walking joint) or is fixed (at its hold angle, or at 0 for a
joint the robot does not have; and the extra frames other tools look for). The URDF writer
(gaitbot.robot.description.urdf_writer) writes these rows as joints; a log or a live view publishes
``transform(row, angle)`` for the turning ones (ROS's /tf) and the fixed ones once (/tf_static), so a tool
that draws the URDF places every link as gaitbot's kinematics do. Names: docs/robot-description.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.body import LEG_LINKS
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.gait.kinematics6 import joint_axis
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.description.tree import axis_angle

ROOT_LINK = "base_link"
TORSO_LINK = "torso"
ALIAS_FRAMES = {"trunk": ROOT_LINK}  # PlaCo's name for the root
SOLE_FRAMES = {"left": ("l_sole", "left_foot"), "right": ("r_sole", "right_foot")}  # REP-120, PlaCo
HIP_FRAMES = {"left": "left_hip_yaw", "right": "right_hip_yaw"}  # PlaCo measures the legs' spacing between these


@dataclass(frozen=True, eq=False)
class JointFrame:
    """One joint of the exported robot: ``child``'s frame in ``parent``'s is ``origin_m`` turned by the joint:
    ``angle`` about ``axis`` if it is ``moving`` (a walking joint), else by the fixed ``angle_rad``."""

    name: str
    parent: str
    child: str
    origin_m: np.ndarray
    axis: np.ndarray
    moving: bool
    angle_rad: float = 0.0

    def transform(self, angle_rad: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(translation (3,), rotation (3, 3)) of the child in the parent at this angle (fixed: its own)."""
        angle = self.angle_rad if angle_rad is None or not self.moving else angle_rad
        return self.origin_m, axis_angle(self.axis, angle) if angle else np.eye(3)


def joint_frames(config: RobotConfig) -> tuple[JointFrame, ...]:
    """Every joint of the exported robot, parents before children."""
    g = config.body.geometry
    joints = {j.name: j for j in config.joints}
    zero, no_axis = np.zeros(3), np.array([1.0, 0.0, 0.0])
    rows = [JointFrame(f"{TORSO_LINK}_frame", ROOT_LINK, TORSO_LINK, zero, no_axis, False)]
    rows += [JointFrame(f"{alias}_frame", target, alias, zero, no_axis, False) for alias, target in ALIAS_FRAMES.items()]
    for side in SIDES:
        offsets = {"hip_yaw": g.hip_in_root(side), "shank": np.array([0.0, 0.0, -g.thigh_m]),
                   "ankle": np.array([0.0, 0.0, -g.shank_m])}
        parent = ROOT_LINK
        for kind, link in zip(LEG_JOINT_KINDS, LEG_LINKS):
            name, child = f"{kind}_{side}", f"{link}_{side}"
            joint = joints.get(name)
            moving = joint is not None and joint.hold_deg is None
            hold = math.radians(joint.hold_deg) if joint is not None and joint.hold_deg is not None else 0.0
            rows.append(JointFrame(name, parent, child, offsets.get(link, zero), np.array(joint_axis(kind, side),
                                                                                         dtype=float), moving, hold))
            parent = child
        rows.append(JointFrame(f"{HIP_FRAMES[side]}_frame", f"hip_yaw_{side}", HIP_FRAMES[side], zero, no_axis, False))
        sole = g.sole_centre_in_foot(side)
        rows += [JointFrame(f"{frame}_frame", parent, frame, sole, no_axis, False) for frame in SOLE_FRAMES[side]]
    return tuple(rows)
