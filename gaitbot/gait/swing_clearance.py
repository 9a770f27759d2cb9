"""How high a swing foot stays while it moves forward: one measure for every walk, flat or terrain.

The walker and the terrain walker lift their swing feet by different means (walk_segments.py, terrain/swing.py);
this module measures the result on the frames alone, so both answer to one rule (docs/gait.md):

- the sole is the whole of it, heel to toe (SOLE_POINTS points on the line between them), and its height is
  each point's height above the ground under that point (the terrain's, if any): the lowest point counts;
- a swing runs from the last frame its foot touches the ground (lowest sole point within ON_GROUND_M) to
  the next such frame; its forward travel is the ankle's, from lift-off to landing;
- **clearance while moving forward**: the least sole height over the frames in which the ankle has covered
  from FORWARD_WINDOW[0] to FORWARD_WINDOW[1] of that travel (a foot leaving or meeting the ground is
  necessarily near it at the two ends); it must be at least the configured clearance;
- **lift-off**: the share of the swing's time before the sole is first LIFTED_M above the ground (a foot
  that leaves the ground slowly scuffs it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import LegGeometry, leg_points
from .joints import PITCH_JOINTS
from .trajectory import Trajectory

SOLE_POINTS = 9
ON_GROUND_M = 1e-5
LIFTED_M = 2e-4
FORWARD_WINDOW = (0.1, 0.9)
MOVES_M = 1e-3  # a swing whose ankle travels less does not move forward
LEGS = ("left", "right")


@dataclass(frozen=True)
class Swing:
    leg: str
    lift_off_s: float
    landing_s: float
    travel_m: float  # the ankle's forward travel from lift-off to landing
    clearance_m: float  # least sole height while the ankle covers FORWARD_WINDOW of the travel (nan: no frame there)
    lift_off_share: float  # share of the swing's time before the sole is LIFTED_M up


def sole_heights(geometry: LegGeometry, trajectory: Trajectory, side: int, terrain=None) -> tuple[np.ndarray, np.ndarray]:
    """(lowest sole point's height above the ground under it, ankle x), per frame, of one foot (0 left, 1 right).
    A planar walk's: the six pitch joints, the legs in the sagittal plane (x forward, z up)."""
    if tuple(trajectory.joints) != PITCH_JOINTS:
        raise ValueError(f"swing clearance is measured on planar walks (the six pitch joints), not {trajectory.joints}")
    q = trajectory.angles_rad[:, 3 * side:3 * side + 3]
    _, ankle, heel, toe = leg_points(geometry, q[:, 0], q[:, 1], q[:, 2])
    root = trajectory.root_xz_m  # the sagittal plane the leg points are in: (x forward, z up)
    heel, toe, ankle = heel + root, toe + root, ankle + root
    u = np.linspace(0.0, 1.0, SOLE_POINTS)
    points = heel[:, None, :] + u[None, :, None] * (toe - heel)[:, None, :]
    ground = terrain.height_at(points[..., 0]) if terrain is not None else 0.0
    return (points[..., 1] - ground).min(axis=1), ankle[:, 0]


def swings(geometry: LegGeometry, trajectory: Trajectory, terrain=None) -> list[Swing]:
    """Every swing of both feet, in time order (see the module docstring)."""
    t = trajectory.t_s
    out = []
    for side, leg in enumerate(LEGS):
        height, ankle_x = sole_heights(geometry, trajectory, side, terrain)
        grounded = np.flatnonzero(height <= ON_GROUND_M)
        for a, b in zip(grounded[:-1], grounded[1:]):
            if b - a < 2:
                continue  # no frame in the air between two on the ground
            travel = ankle_x[b] - ankle_x[a]
            h = height[a:b + 1]
            # a foot set down where it was lifted (a step of 0) does not move forward: no window
            progress = (ankle_x[a:b + 1] - ankle_x[a]) / travel if travel > MOVES_M else np.full(len(h), -1.0)
            window = (progress >= FORWARD_WINDOW[0]) & (progress <= FORWARD_WINDOW[1])
            lifted = int(np.argmax(h > LIFTED_M)) if (h > LIFTED_M).any() else len(h) - 1
            out.append(Swing(leg, float(t[a]), float(t[b]), float(travel),
                             float(h[window].min()) if window.any() else float("nan"),
                             float((t[a + lifted] - t[a]) / (t[b] - t[a]))))
    return sorted(out, key=lambda s: s.lift_off_s)
