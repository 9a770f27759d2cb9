"""The legs an eigen-gait model walks on: which joints it learns, and how its root follows from them.

The model learns joint angles only. A walk's root is not learnt as channels of its own but rebuilt
from foot contact of the synthesised angles, the rule each robot's own walker obeys (docs/eigen-gaits.md,
"The root"): the supporting foot stays still on the floor and the root follows from the leg's kinematics.

- ``PlanarLegs``: the pitch-only robots, six pitch joints. The root moves in the sagittal plane, x
  and height (``root_axes`` "xz"), by the planar walker's contact model (footfall.py: the stance foot
  rolls without slip about its lowest sole point); y = 0.
- ``SpatialLegs``: robots whose legs roll, all twelve leg joints. The root moves in x, y and z
  (``root_axes`` "xyz") by the balanced walker's rule read backwards (footfall3d.py: upright root,
  stance sole flat and still), so its sideways sway and its height come with the angles.

Both answer the same questions: heel strikes of an example file without them, the root of a motion,
a heel strike at a frame, and how far a file's root sits from where these legs put it (a file walked
by another robot's legs stands above or below the floor here).
"""

from __future__ import annotations

import numpy as np

from ..body import BodyGeometry
from ..footfall import detect_heel_strikes, root_from_contact
from ..footfall3d import detect_heel_strikes_3d, heel_strike_at, leg_angles, root_from_contact_3d
from ..geometry import LegGeometry, leg_points
from ..joints import LEG_JOINTS, PITCH_JOINTS
from ..trajectory import HeelStrike, Trajectory, sagittal_to_world


class PlanarLegs:
    """Six pitch joints, the root in the sagittal plane. ``hip_below_root_m`` lifts the root from the hip
    point to the robot's root, as ``gaitbot generate`` writes it (app/planned_walk.py pelvis_root)."""

    root_axes = "xz"
    joints = PITCH_JOINTS

    def __init__(self, geometry: LegGeometry, hip_below_root_m: float = 0.0) -> None:
        self.leg_geometry = geometry
        self.lift_m = float(hip_below_root_m)

    def detect_heel_strikes(self, trajectory: Trajectory) -> list[HeelStrike]:
        return detect_heel_strikes(trajectory, self.leg_geometry)

    def root_from_contact(self, angles_rad, start_root_m) -> np.ndarray:
        """(N, 3) root of angles (N, 6) in PITCH_JOINTS order; only the start's x is used."""
        xz, _ = root_from_contact(self.leg_geometry, angles_rad, np.asarray(start_root_m, dtype=float)[[0, 2]])
        return sagittal_to_world(xz) + [0.0, 0.0, self.lift_m]

    def heel_strike(self, angles_rad, root_m, t_s: float, frame: int, leg: str) -> HeelStrike:
        side = 0 if leg == "left" else 1
        q = np.asarray(angles_rad)[frame, 3 * side:3 * side + 3]
        _, _, heel, _ = leg_points(self.leg_geometry, q[0], q[1], q[2])
        return HeelStrike(float(t_s), leg, float(heel[0] + root_m[frame, 0]))

    def root_height_error_m(self, trajectory: Trajectory) -> float:
        """Median over frames of |file root height - the height these legs give the file's angles|."""
        root = self.root_from_contact(trajectory.angles_of(self.joints), trajectory.root_m[0])
        return float(np.median(np.abs(trajectory.root_m[:, 2] - root[:, 2])))


class SpatialLegs:
    """All twelve leg joints, the root in 3D (footfall3d.py)."""

    root_axes = "xyz"
    joints = LEG_JOINTS

    def __init__(self, body_geometry: BodyGeometry) -> None:
        self.body_geometry = body_geometry
        g = body_geometry
        self.leg_geometry = LegGeometry(thigh=g.thigh_m, shank=g.shank_m, foot=g.foot_m, hip_width=g.hip_width_m,
                                        ankle_height=g.ankle_height_m, heel_back=g.heel_back_m)

    def detect_heel_strikes(self, trajectory: Trajectory) -> list[HeelStrike]:
        return detect_heel_strikes_3d(trajectory, self.body_geometry)

    def root_from_contact(self, angles_rad, start_root_m) -> np.ndarray:
        """(N, 3) root of angles (N, 12) in LEG_JOINTS order; the start's x and y are used."""
        root, _ = root_from_contact_3d(self.body_geometry, angles_rad, np.asarray(start_root_m, dtype=float)[:2])
        return root

    def heel_strike(self, angles_rad, root_m, t_s: float, frame: int, leg: str) -> HeelStrike:
        return heel_strike_at(self.body_geometry, angles_rad, root_m, t_s, frame, leg)

    def root_height_error_m(self, trajectory: Trajectory) -> float:
        root = self.root_from_contact(leg_angles(trajectory.joints, trajectory.angles_rad), trajectory.root_m[0])
        return float(np.median(np.abs(trajectory.root_m[:, 2] - root[:, 2])))
