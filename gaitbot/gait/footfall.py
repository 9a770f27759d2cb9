"""Contact read back from joint angles alone: which foot supports, where the root goes, when heels strike.

A walk made by the walker carries its root and heel strikes; a motion made some other way does
not: cycles synthesised from an eigen-gait model, or a motion recorded from the robot while a
person moves its legs. This module recovers both from the angles with the walker's own contact
model (contact.py, docs/gait-model.md section 3), so such motions obey the same ground rules.

- ``ContactRoot``: frame by frame (a recording is written as it is read), the root that keeps the
  supporting foot still. The supporting foot is the one whose lowest sole point is lower; it stays
  locked while it supports, and the other foot takes over only once it is lower by more than
  ``land_tol`` (so two feet both on the ground do not flicker). At a switch the new stance foot's
  anchor is taken from where it is, so the root never jumps in x. ``root_from_contact`` runs it
  over a whole motion.
- ``heel_strikes_from_heights``: a foot is in the air once its lowest sole point is more than
  ``tol`` above the other foot's; its heel strike is the first frame after that at which it is
  back within a tenth of ``tol`` of the other foot's level. Only the *difference* of the two feet's
  heights matters, so heights relative to the hip (no root known), above flat ground, or each above
  the terrain under it all give the same strikes on flat ground. ``detect_heel_strikes`` applies it
  to a trajectory (``gaitbot eigen fit`` cuts cycles with it; ``gaitbot plot`` marks strikes with it).
- ``swing_clearances``: the walker's clearance rule measured on any flat-ground trajectory, so
  synthesised or recorded walks can be compared with the walker's.
"""

from __future__ import annotations

import numpy as np

from .contact import ankle_in_body, grounded_ankle, leg_pitch, lowest_sole_y
from .geometry import LegGeometry, ankle_position, leg_points
from .joints import PITCH_JOINTS
from .walk_segments import CLEARANCE_WINDOW
from .trajectory import HeelStrike, Trajectory

#: Contact tolerance as a share of the leg length: 2.2 mm for the 0.22 m leg of the shipped robots.
CONTACT_TOL_FRACTION = 0.01


def foot_heights_in_body(geometry: LegGeometry, angles_rad) -> np.ndarray:
    """(N, 2) height of the lowest sole point of the left and right foot relative to the hip (metres)."""
    angles_rad = np.asarray(angles_rad, dtype=float)
    out = []
    for side in (0, 1):
        q = angles_rad[..., 3 * side:3 * side + 3]
        out.append(lowest_sole_y(geometry, ankle_position(geometry, q[..., 0], q[..., 1]), leg_pitch(q)))
    return np.stack(out, axis=-1)


def heel_strikes_from_heights(t_s, heights_m, heel_x_m, tol_m: float) -> list[HeelStrike]:
    """Heel strikes (time order) from per-frame foot heights (N, 2) and world heel x (N, 2), left then right.

    See the module docstring for the rule; ``tol_m`` is the lift that makes a foot airborne."""
    heights_m = np.asarray(heights_m, dtype=float)
    strikes = []
    for side, leg in ((0, "left"), (1, "right")):
        gap = heights_m[:, side] - heights_m[:, 1 - side]
        airborne = False
        for k, value in enumerate(gap):
            if value > tol_m:
                airborne = True
            elif airborne and value <= 0.1 * tol_m:
                strikes.append(HeelStrike(float(t_s[k]), leg, float(heel_x_m[k, side])))
                airborne = False
    return sorted(strikes, key=lambda h: h.t_s)


def heel_world_x(geometry: LegGeometry, trajectory: Trajectory) -> np.ndarray:
    """(N, 2) world x of the left and right heel."""
    out = []
    for side in (0, 1):
        q = trajectory.angles_of(PITCH_JOINTS)[:, 3 * side:3 * side + 3]
        _, _, heel, _ = leg_points(geometry, q[:, 0], q[:, 1], q[:, 2])
        out.append(heel[:, 0] + trajectory.root_m[:, 0])
    return np.column_stack(out)


def detect_heel_strikes(trajectory: Trajectory, geometry: LegGeometry, contact_tol_m: float | None = None):
    """Heel strikes from foot contact (for files without them): list of HeelStrike. Feet heights are
    taken relative to the hip, so a file without a root still gives their times."""
    tol = CONTACT_TOL_FRACTION * geometry.leg_length if contact_tol_m is None else contact_tol_m
    return heel_strikes_from_heights(trajectory.t_s, foot_heights_in_body(geometry, trajectory.angles_of(PITCH_JOINTS)),
                                     heel_world_x(geometry, trajectory), tol)


class ContactRoot:
    """The root (hip point in the world, metres) frame by frame from joint angles, feet on flat ground.

    ``start_x_m``: the root's x at the first frame (its height follows from the supporting foot).
    ``land_tol_m``: how much lower the other foot must be to take over (default a quarter of
    CONTACT_TOL_FRACTION of the leg).
    """

    def __init__(self, geometry: LegGeometry, start_x_m: float = 0.0, land_tol_m: float | None = None) -> None:
        self.geometry = geometry
        self.land_tol_m = 0.25 * CONTACT_TOL_FRACTION * geometry.leg_length if land_tol_m is None else land_tol_m
        self._start_x_m = float(start_x_m)
        self.stance: int | None = None  # 0 left, 1 right; None before the first frame
        self._anchor_x_m = 0.0
        self._root = None

    def _anchor_for(self, ankle_x_body: float, pitch: float, root_x: float) -> float:
        # grounded_ankle is x-linear in the anchor with unit slope: invert it at this frame
        return float(root_x + ankle_x_body - grounded_ankle(self.geometry, 0.0, pitch)[0])

    def update(self, angles_rad) -> np.ndarray:
        """Root (2,) for the next frame's six joint angles (radians, PITCH_JOINTS order)."""
        q = np.asarray(angles_rad, dtype=float)
        heights = foot_heights_in_body(self.geometry, q)
        legs = (q[0:3], q[3:6])
        if self.stance is None:
            self.stance = int(np.argmin(heights))
            ankle = ankle_in_body(self.geometry, legs[self.stance])
            self._anchor_x_m = self._anchor_for(ankle[0], leg_pitch(legs[self.stance]), self._start_x_m)
        else:
            other = 1 - self.stance
            if heights[other] < heights[self.stance] - self.land_tol_m:
                ankle = ankle_in_body(self.geometry, legs[other])
                self._anchor_x_m = self._anchor_for(ankle[0], leg_pitch(legs[other]), self._root[0])
                self.stance = other
        leg = legs[self.stance]
        self._root = grounded_ankle(self.geometry, self._anchor_x_m, leg_pitch(leg)) - ankle_in_body(self.geometry, leg)
        return self._root


def root_from_contact(geometry: LegGeometry, angles_rad, start_root, land_tol: float | None = None):
    """Root (N, 2) keeping the supporting foot still, and the stance leg per frame (0 left, 1 right).

    ``start_root``: the first frame's root; only its x is used (the height follows from contact)."""
    tracker = ContactRoot(geometry, float(np.asarray(start_root, dtype=float)[0]), land_tol)
    angles_rad = np.asarray(angles_rad, dtype=float)
    root = np.empty((len(angles_rad), 2))
    stance = np.empty(len(angles_rad), dtype=int)
    for k, q in enumerate(angles_rad):
        root[k] = tracker.update(q)
        stance[k] = tracker.stance
    return root, stance


def swing_clearances(geometry: LegGeometry, trajectory, tol_m: float | None = None) -> list[tuple[HeelStrike, float]]:
    """Per heel strike: the least height of the whole swing sole above flat ground from 20% to 80% of
    the swing that ends in it (the walker's clearance rule, walk_segments.CLEARANCE_WINDOW).

    The swing runs from the last frame the foot was within ``tol_m`` (default CONTACT_TOL_FRACTION of
    the leg) of the ground to the frame before it is back; heights use the trajectory's root, so the
    walker's walks and walks with a root from contact are measured alike. Heel strikes are the file's,
    else detected (``detect_heel_strikes``); strikes with no airborne frames before them are skipped."""
    tol = CONTACT_TOL_FRACTION * geometry.leg_length if tol_m is None else tol_m
    heights = foot_heights_in_body(geometry, trajectory.angles_of(PITCH_JOINTS)) + trajectory.root_m[:, 2:3]
    out = []
    for strike in trajectory.heel_strikes or detect_heel_strikes(trajectory, geometry):
        side = 0 if strike.leg == "left" else 1
        end = int(np.argmin(np.abs(trajectory.t_s - strike.t_s)))
        while end > 0 and heights[end, side] <= tol:
            end -= 1
        start = end
        while start > 0 and heights[start - 1, side] > tol:
            start -= 1
        if end <= start:
            continue
        lo, hi = start + CLEARANCE_WINDOW[0] * (end - start), start + CLEARANCE_WINDOW[1] * (end - start)
        window = np.arange(int(np.ceil(lo)), int(np.floor(hi)) + 1)
        if len(window):
            out.append((strike, float(heights[window, side].min())))
    return out
