"""A robot's body for the 3D gait and the balance check: leg geometry in 3D and every link's mass.

Frames (docs/gait-model.md section 8): the root is the pelvis, x forward, y left, z up (REP-103).
The hip point (where the hip axes meet) lies ``hip_below_root_m`` below the root and half the hip
width to each side; the ankle point (where the ankle axes meet) ``thigh_m + shank_m`` below it in
the straight leg, the sole ``ankle_height_m`` under the ankle point, its centre ``foot_m / 2 -
heel_back_m`` ahead of it and ``sole_outward_m`` outward (away from the midline).

Links per leg, from the pelvis down: hip_yaw, hip_roll, thigh, shank, ankle, foot (each turns with
the joint above it). A link's centre of mass and inertia are given for the LEFT leg in a frame
parallel to the root at the zero pose, origin at the link's joint point (the hip point for hip_yaw,
hip_roll and thigh; the knee for the shank; the ankle point for ankle and foot); the right leg is
its mirror image. The torso link holds everything above the hips, held arms and head included.
The robot room builds a BodyModel from the config's ``[geometry]``, ``[links.*]`` or ``[mass]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEG_LINKS = ("hip_yaw", "hip_roll", "thigh", "shank", "ankle", "foot")
SIDE_SIGN = {"left": 1.0, "right": -1.0}
_MIRROR = np.diag([1.0, -1.0, 1.0])


@dataclass(frozen=True)
class BodyGeometry:
    """Leg geometry in metres (the module docstring says where each length sits)."""

    thigh_m: float
    shank_m: float
    foot_m: float
    foot_width_m: float
    hip_width_m: float
    ankle_height_m: float
    heel_back_m: float
    sole_outward_m: float = 0.0
    hip_below_root_m: float = 0.0

    @property
    def leg_length_m(self) -> float:
        return self.thigh_m + self.shank_m

    def hip_in_root(self, side: str) -> np.ndarray:
        """The hip point in the root frame."""
        return np.array([0.0, SIDE_SIGN[side] * self.hip_width_m / 2, -self.hip_below_root_m])

    def sole_centre_in_foot(self, side: str) -> np.ndarray:
        """The sole's centre (on its underside) in the foot frame, whose origin is the ankle point."""
        return np.array([self.foot_m / 2 - self.heel_back_m, SIDE_SIGN[side] * self.sole_outward_m,
                         -self.ankle_height_m])

    @property
    def standing_root_height_m(self) -> float:
        """The root's height standing straight, soles flat on the floor."""
        return self.leg_length_m + self.ankle_height_m + self.hip_below_root_m


@dataclass(frozen=True, eq=False)
class LinkInertial:
    """A rigid link: mass (kg), centre of mass (m, (3,)) and inertia about it (kg m^2, (3, 3)) in its frame."""

    mass_kg: float
    com_m: np.ndarray
    inertia_kg_m2: np.ndarray

    def mirrored(self) -> "LinkInertial":
        """The right leg's link from the left one's: y -> -y (Ixy and Iyz change sign)."""
        return LinkInertial(self.mass_kg, _MIRROR @ self.com_m, _MIRROR @ self.inertia_kg_m2 @ _MIRROR)

    def scaled(self, mass_factor: float = 1.0, com_factor: float = 1.0) -> "LinkInertial":
        """The same link heavier (inertia with it) and its centre of mass further from the joint."""
        return LinkInertial(self.mass_kg * mass_factor, self.com_m * com_factor, self.inertia_kg_m2 * mass_factor)


def inertia_matrix(ixx: float, iyy: float, izz: float, ixy: float = 0.0, ixz: float = 0.0,
                   iyz: float = 0.0) -> np.ndarray:
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def box_inertia(mass_kg: float, size_m) -> np.ndarray:
    """A uniform solid box's inertia about its centre (size: full lengths along x, y, z)."""
    x, y, z = size_m
    return np.diag([y * y + z * z, x * x + z * z, x * x + y * y]) * mass_kg / 12.0


@dataclass(frozen=True, eq=False)
class BodyModel:
    """Geometry plus the torso and the left leg's six links (``LEG_LINKS``); the right leg mirrors them."""

    geometry: BodyGeometry
    torso: LinkInertial
    leg_links: dict

    def leg_link(self, name: str, side: str) -> LinkInertial:
        link = self.leg_links[name]
        return link if side == "left" else link.mirrored()

    @property
    def total_kg(self) -> float:
        return self.torso.mass_kg + 2.0 * sum(link.mass_kg for link in self.leg_links.values())

    @classmethod
    def from_segment_masses(cls, geometry: BodyGeometry, torso_kg: float, thigh_kg: float, shank_kg: float,
                            foot_kg: float, torso_height_m: float) -> "BodyModel":
        """A body from four masses (the planar robots' ``[mass]`` table): each segment a uniform solid,
        thigh and shank centred on their bones, the foot on its sole, the torso a box of the given
        height standing on the hips. The hip and ankle links are massless (pitch-only legs)."""
        tiny = LinkInertial(0.0, np.zeros(3), np.zeros((3, 3)))
        width = max(geometry.hip_width_m, 0.02)
        foot_centre = np.array([geometry.foot_m / 2 - geometry.heel_back_m, 0.0, -geometry.ankle_height_m / 2])

        def rod(mass_kg: float, length_m: float) -> LinkInertial:
            return LinkInertial(mass_kg, np.array([0.0, 0.0, -length_m / 2]),
                                box_inertia(mass_kg, (0.2 * length_m, 0.2 * length_m, length_m)))

        torso = LinkInertial(torso_kg, np.array([0.0, 0.0, torso_height_m / 2 - geometry.hip_below_root_m]),
                             box_inertia(torso_kg, (0.5 * torso_height_m, width, torso_height_m)))
        links = {"hip_yaw": tiny, "hip_roll": tiny, "thigh": rod(thigh_kg, geometry.thigh_m),
                 "shank": rod(shank_kg, geometry.shank_m), "ankle": tiny,
                 "foot": LinkInertial(foot_kg, foot_centre, box_inertia(foot_kg, (geometry.foot_m, 0.4 * width,
                                                                                   geometry.ankle_height_m or 0.01)))}
        return cls(geometry, torso, links)
