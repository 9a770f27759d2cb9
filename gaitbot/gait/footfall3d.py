"""Contact read back from the twelve leg joint angles of a 3D robot: heel strikes and the root.

The 3D counterpart of footfall.py, for motions that carry no root of their own or whose root must
follow their angles (cycles synthesised from an eigen-gait model of a robot whose legs roll). The
balanced walker keeps the root upright and every stance sole flat and still on the floor
(docs/balance.md), so the same rule read backwards gives its root from its angles:

- the feet are seen from an upright root (no torso attitude): each sole's four corners by the
  6-joint leg kinematics (kinematics6.sole_corners);
- the supporting foot keeps supporting until the other, having left the floor (its lowest corner more
  than ``lift_tol_m`` above the stance foot's), comes back down to it: the other foot supports from
  its heel strike on (footfall.py's rule). In double support both soles are still, so the hand-over
  is exact there; waiting instead for the old foot to rise a tolerance would take its first frame of
  motion for contact, a fraction of a millimetre that adds up step after step;
- the stance sole's centre stays where it is in x and y; the lowest sole corner of either foot is on
  the floor (z = 0). When the other foot takes over, its anchor is where it is at that frame with the
  root the old stance foot gives, so the root's x and y never jump (a one-frame pause would be a ZMP
  spike of centimetres);
- heel strikes come from the feet's heights with footfall.py's rule (``heel_strikes_from_heights``),
  the heel at the back of the sole, the strike's y at the sole's centre, as the balanced walker
  writes them.
"""

from __future__ import annotations

import numpy as np

from .body import BodyGeometry
from .footfall import CONTACT_TOL_FRACTION, heel_strikes_from_heights
from .joints import LEG_JOINTS, SIDES
from .kinematics6 import foot_pose, sole_corners
from .trajectory import HeelStrike, Trajectory


def leg_angles(trajectory_joints, angles_rad) -> np.ndarray:
    """(N, 12) angles in LEG_JOINTS order from (N, J) angles of ``trajectory_joints``; joints missing stay 0."""
    angles_rad = np.asarray(angles_rad, dtype=float)
    out = np.zeros(angles_rad.shape[:-1] + (len(LEG_JOINTS),))
    for i, name in enumerate(trajectory_joints):
        out[..., LEG_JOINTS.index(name)] = angles_rad[..., i]
    return out


def _leg(q12, side: str) -> np.ndarray:
    return q12[..., 6 * SIDES.index(side):6 * SIDES.index(side) + 6]


def feet_in_root(geometry: BodyGeometry, q12) -> dict:
    """Per side, in the upright root's frame: the sole corners (N, 4, 3), the sole centre (N, 3) and the
    heel (the middle of the sole's back edge, (N, 3))."""
    out = {}
    for side in SIDES:
        q = _leg(q12, side)
        ankle, rot = foot_pose(geometry, side, q)
        centre = geometry.sole_centre_in_foot(side)
        heel = centre - [geometry.foot_m / 2, 0.0, 0.0]
        out[side] = (sole_corners(geometry, side, q), ankle + rot @ centre, ankle + rot @ heel)
    return out


def foot_heights_3d(geometry: BodyGeometry, q12) -> np.ndarray:
    """(N, 2) height of each foot's lowest sole corner relative to the root (left, right; metres)."""
    feet = feet_in_root(geometry, q12)
    return np.column_stack([feet[side][0][..., 2].min(axis=-1) for side in SIDES])


def root_from_contact_3d(geometry: BodyGeometry, q12, start_xy_m=(0.0, 0.0), lift_tol_m: float | None = None):
    """Root (N, 3) keeping the supporting sole still and on the floor, and the stance leg per frame (0 left,
    1 right); the module docstring gives the rule. ``start_xy_m``: the first frame's root x and y."""
    q12 = np.asarray(q12, dtype=float)
    tol = CONTACT_TOL_FRACTION * geometry.leg_length_m if lift_tol_m is None else lift_tol_m
    feet = feet_in_root(geometry, q12)
    low = np.column_stack([feet[side][0][:, :, 2].min(axis=1) for side in SIDES])  # (N, 2), root frame
    centre = np.stack([feet[side][1][:, :2] for side in SIDES], axis=1)  # (N, 2, 2)
    n = len(q12)
    root = np.empty((n, 3))
    stance = np.empty(n, dtype=int)
    lifted = np.flatnonzero(np.abs(low[:, 0] - low[:, 1]) > tol)
    # the first foot to leave the floor swings: the other one supports from the start
    leg = int(low[lifted[0], 0] > low[lifted[0], 1]) if len(lifted) else int(np.argmin(low[0]))
    anchor = np.asarray(start_xy_m, dtype=float)[:2] + centre[0, leg]
    airborne = False
    for k in range(n):
        xy = anchor - centre[k, leg]
        other = 1 - leg
        gap = low[k, other] - low[k, leg]  # how far the other foot is above the stance foot
        if gap > tol:
            airborne = True
        # it takes over at its heel strike (footfall.py's rule), or at once if the stance foot left the floor
        if (airborne and gap <= 0.1 * tol) or gap < -tol:
            leg, airborne = other, False
            anchor = xy + centre[k, leg]
        root[k, :2] = xy
        root[k, 2] = -low[k].min()  # the lowest sole corner of either foot on the floor
        stance[k] = leg
    return root, stance


def detect_heel_strikes_3d(trajectory: Trajectory, geometry: BodyGeometry,
                           contact_tol_m: float | None = None) -> list[HeelStrike]:
    """Heel strikes of a 3D walk from foot contact (for files without them): footfall.py's rule on the
    feet's heights seen from the root, each strike at its heel's world x and its sole centre's world y."""
    tol = CONTACT_TOL_FRACTION * geometry.leg_length_m if contact_tol_m is None else contact_tol_m
    q12 = leg_angles(trajectory.joints, trajectory.angles_rad)
    feet = feet_in_root(geometry, q12)
    heights = np.column_stack([feet[side][0][:, :, 2].min(axis=1) for side in SIDES])
    heel_x = np.column_stack([feet[side][2][:, 0] + trajectory.root_m[:, 0] for side in SIDES])
    strikes = heel_strikes_from_heights(trajectory.t_s, heights, heel_x, tol)
    frames = {float(t): k for k, t in enumerate(trajectory.t_s)}
    out = []
    for h in strikes:
        k = frames[h.t_s]
        side = h.leg
        out.append(HeelStrike(h.t_s, side, h.x_m, float(feet[side][1][k, 1] + trajectory.root_m[k, 1])))
    return out


def heel_strike_at(geometry: BodyGeometry, q12, root_m, t_s: float, frame: int, leg: str) -> HeelStrike:
    """The heel strike of ``leg`` at ``frame`` of a motion whose root is ``root_m`` (N, 3)."""
    feet = feet_in_root(geometry, np.asarray(q12, dtype=float)[frame:frame + 1])
    _, centre, heel = feet[leg]
    return HeelStrike(float(t_s), leg, float(heel[0, 0] + root_m[frame, 0]), float(centre[0, 1] + root_m[frame, 1]))
