"""Where a leg can put its foot: the 2-link leg's reach and its joint ranges, with a spare margin.

Every pelvis point the terrain walker considers (mid-stance points, the grid search's cells, the
hand-over points) is tested here: the hip-to-ankle distance must keep the knee between MIN_KNEE_RAD
and the knee's upper limit, and the hip, knee and ankle angles from IK must lie inside their
ranges by ``spare``. A swing foot's ankle is left out where the caller says so: its sole is tipped
to fit once the pelvis is known (swing.py).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..geometry import LegGeometry, leg_ik
from ..walk_segments import MIN_KNEE_RAD, crouch_leg_scale

FREE_KNEE_RAD = np.radians(150.0)  # the knee's bend when no joint ranges are given
MOTION_SHARE = 0.8  # the search aims below this share of the limits (its samples are sparse); the walk is then
# held to the robot's planning margin as a whole (gaitbot.robot.planar_fit stretches its cycle if needed)


@dataclass(frozen=True)
class LegRange:
    """A leg's reachable set. Angles in radians: joint_lo/joint_hi are (hip, knee, ankle) or None."""

    geometry: LegGeometry
    joint_lo: tuple[float, float, float] | None = None
    joint_hi: tuple[float, float, float] | None = None
    spare: float = np.radians(1.0)
    min_knee: float = MIN_KNEE_RAD
    speed: tuple[float, float, float] | None = None  # rad/s, hip, knee, ankle
    accel: tuple[float, float, float] | None = None  # rad/s^2

    @cached_property
    def reach(self) -> float:
        """Longest hip-to-ankle distance (the knee bent min_knee, away from the straight-leg singularity)."""
        return self.geometry.leg_length * crouch_leg_scale(self.geometry, self.min_knee)

    @cached_property
    def reach_min(self) -> float:
        knee = self.joint_hi[1] - self.spare if self.joint_hi is not None else FREE_KNEE_RAD
        return self.geometry.leg_length * crouch_leg_scale(self.geometry, knee)

    def with_spare(self, spare: float, min_knee: float) -> LegRange:
        return replace(self, spare=spare, min_knee=min_knee)

    def motion_excess(self, q, dt: float, moving=None) -> np.ndarray:
        """How far joint angles q (w, n, 3) sampled every dt seconds go beyond MOTION_SHARE of the joints'
        speed and acceleration limits, per row (w,), in radians (speed excess times dt plus acceleration
        excess times dt^2, summed). ``moving`` (w, n) marks the samples that belong to the motion (a
        foot changing from support to swing between two samples is not one motion). 0 if no limits."""
        q = np.asarray(q, dtype=float)
        out = np.zeros(q.shape[0])
        keep = np.ones(q.shape[:2], bool) if moving is None else np.asarray(moving, bool)
        if self.speed is not None:
            both = keep[:, 1:] & keep[:, :-1]
            speed = np.abs(np.diff(q, axis=1)) / dt
            over = np.maximum(speed - MOTION_SHARE * np.asarray(self.speed), 0.0) * dt
            out += (over.sum(axis=2) * both).sum(axis=1)
        if self.accel is not None and q.shape[1] > 2:
            three = keep[:, 2:] & keep[:, 1:-1] & keep[:, :-2]
            acc = np.abs(q[:, 2:] - 2 * q[:, 1:-1] + q[:, :-2]) / dt**2
            over = np.maximum(acc - MOTION_SHARE * np.asarray(self.accel), 0.0) * dt**2
            out += (over.sum(axis=2) * three).sum(axis=1)
        return out

    def excess(self, pose, root, check_ankle=True) -> np.ndarray:
        """Per row, how far the leg from a hip at ``root`` (n, 2) is from putting its foot at ``pose`` (n, 3)
        within its reach and ranges: 0 where it can; else the distance beyond the reach in leg lengths
        plus the angles beyond the ranges in radians. ``check_ankle`` (bool or (n,) bools) says where the
        ankle's range counts. The size lets a search find its way to a feasible point."""
        return self.check(pose, root, check_ankle)[0]

    def check(self, pose, root, check_ankle=True):
        """(``excess``, the leg angles (n, 3) by IK with an out-of-reach foot pulled back to the reach)."""
        pose, root = np.atleast_2d(pose), np.atleast_2d(root)
        rel = pose[:, :2] - root
        d = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-12)
        out = (np.maximum(d - self.reach, 0.0) + np.maximum(self.reach_min - d, 0.0)) / self.geometry.leg_length
        q = leg_ik(self.geometry, rel * np.minimum(1.0, self.reach / d)[:, None], pose[:, 2] + np.zeros(len(rel)))
        if self.joint_lo is None:
            return out, q
        lo, hi = np.asarray(self.joint_lo) + self.spare, np.asarray(self.joint_hi) - self.spare
        beyond = np.maximum(lo - q, 0.0) + np.maximum(q - hi, 0.0)
        beyond[:, 2] *= np.broadcast_to(np.asarray(check_ankle, dtype=bool), (len(rel),))
        return out + beyond.sum(axis=1), q

    def fits(self, pose, root, check_ankle=True) -> np.ndarray:
        """Per row: can the leg from a hip at ``root`` (n, 2) put its foot at ``pose`` (n, 3)?"""
        return self.excess(pose, root, check_ankle) <= 0.0

    def angles(self, pose, root):
        """Leg angles (n, 3) by IK; a foot out of reach is pulled back to the reach (callers test ``fits``)."""
        return self.check(pose, root)[1]
