"""The telemetry of a planned walk, frame by frame: computed once before the walk, indexed in its loop.

From the trajectory sent to the servos (goals) and the planned body motion (root, torso attitude, the
angles the body follows), gaitbot.check.balance gives the centre of mass, the ZMP, the support polygon
and the soles for every frame, as the preflight check sees them; :meth:`PlannedFrames.frame` then only
picks row k, so a frame costs no computation here.
"""

from __future__ import annotations

import numpy as np

from gaitbot.check.balance import balance_trace
from gaitbot.check.preflight import robot_angles_deg
from gaitbot.gait.joints import SIDES
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig
from gaitbot.view.telemetry import FrameTelemetry


def sole_poses(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centres (N, 3) and rotations (N, 3, 3) of a sole from its four underside corners (N, 4, 3): front left,
    back left, back right, front right (gaitbot.gait.kinematics6.SOLE_CORNER_SIGNS)."""
    forward = corners[:, 0] - corners[:, 1]
    left = corners[:, 0] - corners[:, 3]
    x = forward / np.linalg.norm(forward, axis=1, keepdims=True)
    y = left - x * np.einsum("ni,ni->n", left, x)[:, None]
    y = y / np.linalg.norm(y, axis=1, keepdims=True)
    return corners.mean(axis=1), np.stack([x, y, np.cross(x, y)], axis=2)


class PlannedFrames:
    """Row k of a walk as a FrameTelemetry (``health``, ``read_back`` and ``command`` added by the caller)."""

    def __init__(self, config: RobotConfig, goals: Trajectory, planned: Trajectory | None = None) -> None:
        planned = planned if planned is not None else goals
        self.joints = tuple(config.joint_names)
        self.t_s = goals.t_s - goals.t_s[0]
        self.goals_rad = np.radians(robot_angles_deg(config, goals))
        trace = balance_trace(config, planned, robot_angles_deg(config, planned))
        self.root_m = planned.root_m
        self.rpy_rad = planned.torso_rpy_rad if planned.torso_rpy_rad is not None else np.zeros((len(goals.t_s), 3))
        self.com_m, self.zmp_m, self.support = trace.com_m, trace.zmp_m, trace.support
        self.soles = {side: sole_poses(trace.soles[side]) for side in SIDES}

    def __len__(self) -> int:
        return len(self.t_s)

    def frame(self, k: int, **extra) -> FrameTelemetry:
        """Frame k (clamped to the walk: the stop ramp after it repeats the last)."""
        k = min(max(int(k), 0), len(self.t_s) - 1)
        soles = {side: (centre[k], rotation[k]) for side, (centre, rotation) in self.soles.items()}
        return FrameTelemetry(t_s=float(self.t_s[k]), joints=self.joints, goals_rad=self.goals_rad[k],
                              root_m=self.root_m[k], root_rpy_rad=self.rpy_rad[k], com_m=self.com_m[k],
                              zmp_m=self.zmp_m[k], soles_m=soles, support_m=self.support[k], **extra)
