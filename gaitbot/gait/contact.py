"""Feet on the ground: a rolling sole, and the body's translation from the supporting foot.

Jing et al. 2015 section 2.2 locks the supporting foot's heel, then its toe once the foot is parallel
to the ground, and moves the root by the contact point's displacement (eq. 9). Using "the lower
of heel and toe is the contact" (docs/gait-model.md section 3), that incremental rule has a closed
form: a foot rolling without slip is fixed by one number, its *anchor* (the heel's x when the
sole is flat), and its pitch. Heel down (pitch >= 0): heel at (anchor, 0). Toe down: toe at
(anchor + foot, 0). Both agree when flat, so the contact switch never jumps, and the root is
``ankle_world - ankle_in_body`` at every frame with no accumulated error.
"""

from __future__ import annotations

import numpy as np

from .geometry import LegGeometry, ankle_position, foot_points, foot_pitch


def leg_pitch(q):
    """Sole pitch of a leg pose ``q`` (..., 3) = hip, knee, ankle flexion in radians."""
    q = np.asarray(q)
    return foot_pitch(q[..., 0], q[..., 1], q[..., 2])


def ankle_in_body(geometry: LegGeometry, q):
    """Ankle relative to the hip for leg pose(s) ``q`` (..., 3)."""
    q = np.asarray(q)
    return ankle_position(geometry, q[..., 0], q[..., 1])


def grounded_ankle(geometry: LegGeometry, anchor_x, pitch, ground_y: float = 0.0):
    """World ankle of a foot resting on flat ground, rolling about its lower point.

    ``anchor_x`` is the heel's x when the sole is flat; returns (..., 2).
    """
    pitch = np.asarray(pitch, dtype=float)
    c, s = np.cos(pitch), np.sin(pitch)
    heel_down = pitch >= 0.0
    # contact point on the sole, in the foot frame relative to the ankle
    px = np.where(heel_down, -geometry.heel_back, geometry.toe_forward)
    py = -geometry.ankle_height
    contact_x = np.where(heel_down, anchor_x, np.asarray(anchor_x) + geometry.foot)
    x = contact_x - (px * c - py * s)
    y = ground_y - (px * s + py * c)
    return np.stack([x, y], axis=-1)


def heel_pinned_ankle(geometry: LegGeometry, heel_x, pitch, ground_y: float = 0.0):
    """World ankle of a foot whose heel is at (heel_x, ground) with the given pitch (any sign)."""
    pitch = np.asarray(pitch, dtype=float)
    c, s = np.cos(pitch), np.sin(pitch)
    px, py = -geometry.heel_back, -geometry.ankle_height
    return np.stack([heel_x - (px * c - py * s), ground_y - (px * s + py * c)], axis=-1)


def root_from_stance(geometry: LegGeometry, anchor_x, q_stance):
    """Hip position in the world that keeps the stance foot's contact point still (eq. 9, closed form)."""
    return grounded_ankle(geometry, anchor_x, leg_pitch(q_stance)) - ankle_in_body(geometry, q_stance)


def lowest_sole_y(geometry: LegGeometry, ankle_world, pitch):
    """Height of the lowest point of the sole (heel or toe: the sole is a straight segment)."""
    heel, toe = foot_points(geometry, ankle_world, pitch)
    return np.minimum(heel[..., 1], toe[..., 1])
