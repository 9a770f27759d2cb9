"""Leg geometry and planar kinematics of one leg (sagittal plane, x forward, y up).

Hip at the origin. Thigh direction is angle h from the downward vertical, shank h - k, foot
(h - k) + a from the horizontal, toe up positive (docs/gait-model.md section 1). The foot is a
rigid sole: heel and toe are points on it, given relative to the ankle in the foot's frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LegGeometry:
    """Lengths in metres (or leg lengths for the normalised human leg).

    thigh: hip to knee; shank: knee to ankle; foot: heel to toe along the sole;
    ankle_height: ankle above the sole (0 for Jing et al.'s leg, whose ankle lies on the sole);
    heel_back: heel behind the ankle along the sole (0 for Jing et al.'s leg: heel is the ankle
    projected on the sole line); hip_width: lateral distance between the hips.
    """

    thigh: float = 0.466
    shank: float = 0.534
    foot: float = 0.20
    hip_width: float = 0.356
    ankle_height: float = 0.0
    heel_back: float = 0.0

    def __post_init__(self) -> None:
        for name in ("thigh", "shank", "foot"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive length, got {value!r}")
        for name in ("hip_width", "ankle_height", "heel_back"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a length of 0 or more, got {value!r}")
        if self.heel_back >= self.foot:
            raise ValueError(f"heel_back ({self.heel_back}) must be shorter than the foot ({self.foot})")

    @property
    def leg_length(self) -> float:
        """LLen = thigh + shank: the unit of RV, RL and normalised step lengths."""
        return self.thigh + self.shank

    @property
    def toe_forward(self) -> float:
        """Toe ahead of the ankle along the sole."""
        return self.foot - self.heel_back

    @property
    def standing_hip_height(self) -> float:
        """Hip above the ground when standing straight."""
        return self.leg_length + self.ankle_height


# Jing et al. 2015, Table 1: the reference human leg, leg length 1.0.
TABLE1_LEG = LegGeometry()


def ankle_position(geometry: LegGeometry, hip, knee):
    """Ankle relative to the hip: arrays of (..., 2)."""
    hip = np.asarray(hip)
    shank_dir = hip - np.asarray(knee)
    x = geometry.thigh * np.sin(hip) + geometry.shank * np.sin(shank_dir)
    y = -geometry.thigh * np.cos(hip) - geometry.shank * np.cos(shank_dir)
    return np.stack([x, y], axis=-1)


def foot_pitch(hip, knee, ankle):
    """Sole angle from the horizontal, toe up positive: (h - k) + a."""
    return np.asarray(hip) - np.asarray(knee) + np.asarray(ankle)


def foot_points(geometry: LegGeometry, ankle_xy, pitch):
    """Heel and toe from the ankle point and the sole pitch: two arrays of (..., 2)."""
    ankle_xy = np.asarray(ankle_xy)
    c, s = np.cos(pitch), np.sin(pitch)
    # the sole lies ankle_height below the ankle, perpendicular to the sole direction (c, s)
    sole_x = ankle_xy[..., 0] + geometry.ankle_height * s
    sole_y = ankle_xy[..., 1] - geometry.ankle_height * c
    heel = np.stack([sole_x - geometry.heel_back * c, sole_y - geometry.heel_back * s], axis=-1)
    toe = np.stack([sole_x + geometry.toe_forward * c, sole_y + geometry.toe_forward * s], axis=-1)
    return heel, toe


def leg_points(geometry: LegGeometry, hip, knee, ankle):
    """Knee, ankle, heel and toe of one leg relative to its hip, each (..., 2)."""
    hip = np.asarray(hip)
    knee_xy = np.stack([geometry.thigh * np.sin(hip), -geometry.thigh * np.cos(hip)], axis=-1)
    ankle_xy = ankle_position(geometry, hip, knee)
    heel, toe = foot_points(geometry, ankle_xy, foot_pitch(hip, knee, ankle))
    return knee_xy, ankle_xy, heel, toe


def leg_ik(geometry: LegGeometry, ankle_xy, pitch):
    """2-link inverse kinematics: hip, knee, ankle flexion placing the ankle at ``ankle_xy``
    (relative to the hip) with the sole at ``pitch``; knee bends forward-of-shank (k >= 0).

    Raises ValueError where the ankle is out of reach; callers keep targets inside it.
    """
    ankle_xy = np.asarray(ankle_xy, dtype=float)
    x, y = ankle_xy[..., 0], ankle_xy[..., 1]
    d2 = x * x + y * y
    a, b = geometry.thigh, geometry.shank
    cos_k = (d2 - a * a - b * b) / (2 * a * b)
    if np.any(cos_k > 1 + 1e-12) or np.any(cos_k < -1 - 1e-12):
        raise ValueError("ankle target out of the leg's reach")
    # knee flexion k: the angle between thigh and shank directions; cos(k) = cos_k (k >= 0)
    knee = np.arccos(np.clip(cos_k, -1.0, 1.0))
    # direction of the hip->ankle line from the downward vertical
    line = np.arctan2(x, -y)
    # the thigh sits ahead of that line by the angle opposite the shank in the hip-knee-ankle triangle
    offset = np.arctan2(b * np.sin(knee), a + b * np.cos(knee))
    hip = line + offset
    ankle = pitch - (hip - knee)
    return np.stack([hip, knee, ankle], axis=-1)
