"""Step timing, footholds and the ZMP reference of a straight balanced walk (docs/balance.md).

A step of length L lands the swinging foot L beyond the previous heel strike (Jing et al.'s step length:
heel strike to heel strike), the ankles hip_width apart. Each step is a whole number of frames
(cycle / 2, rounded as the planar walker does): first a double support in which the ZMP reference moves
smoothly (C2) from the old stance foot's reference point to the new one's, then a single support in
which it stays there while the other foot swings. The first step's double support lasts a whole step:
the weight shifts onto the first stance foot before any foot lifts. After the last step the trailing
foot closes beside the leading one and the ZMP returns to between the feet.

A foot's ZMP reference point is its sole's centre moved ``zmp_forward_m`` forward and ``zmp_inward_m``
towards the midline: a point well inside the sole, away from the edges the robot would tip over.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.body import SIDE_SIGN, BodyGeometry

MIN_STEP_FRAMES = 6
MIN_SINGLE_SUPPORT_FRAMES = 4


def smootherstep(u):
    """0 -> 1 with zero first and second derivatives at both ends (C2 joins)."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    return u * u * u * (u * (6 * u - 15) + 10)


@dataclass(frozen=True)
class Timing:
    """Frames per step, split into double support (first) and single support."""

    rate_hz: float
    step_frames: int
    ds_frames: int

    @classmethod
    def of(cls, cycle_s: float, rate_hz: float, double_support_share: float) -> "Timing":
        step = max(MIN_STEP_FRAMES, round(cycle_s / 2.0 * rate_hz))
        ds = int(np.clip(round(double_support_share * step), 1, step - MIN_SINGLE_SUPPORT_FRAMES))
        return cls(rate_hz, step, ds)

    @property
    def ss_frames(self) -> int:
        return self.step_frames - self.ds_frames

    @property
    def cycle_s(self) -> float:
        """The cycle actually walked: two whole-frame steps."""
        return 2 * self.step_frames / self.rate_hz


@dataclass(frozen=True)
class FootPlacement:
    """Where a foot's ankle point stands (world x, y in metres; the sole flat on the floor) and which way
    its toe points (yaw_rad, counter-clockwise from the world's x axis; 0: straight ahead)."""

    side: str
    x_m: float
    y_m: float
    yaw_rad: float = 0.0

    def to_world(self, forward_m: float, left_m: float) -> np.ndarray:
        """A point given in the foot's frame (forward, left of the ankle point) in the world (x, y)."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return np.array([self.x_m + c * forward_m - s * left_m, self.y_m + s * forward_m + c * left_m])


def sole_centre_xy(geometry: BodyGeometry, foot: FootPlacement) -> np.ndarray:
    s = SIDE_SIGN[foot.side]
    if foot.yaw_rad != 0.0:
        return foot.to_world(geometry.foot_m / 2 - geometry.heel_back_m, s * geometry.sole_outward_m)
    return np.array([foot.x_m + geometry.foot_m / 2 - geometry.heel_back_m, foot.y_m + s * geometry.sole_outward_m])


def zmp_point(geometry: BodyGeometry, balance: BalanceSettings, foot: FootPlacement) -> np.ndarray:
    """The ZMP reference point (x, y) of a foot standing at ``foot`` (offsets in the foot's own frame)."""
    s = SIDE_SIGN[foot.side]
    if foot.yaw_rad != 0.0:
        return foot.to_world(geometry.foot_m / 2 - geometry.heel_back_m + balance.zmp_forward_m,
                             s * (geometry.sole_outward_m - balance.zmp_inward_m))
    return sole_centre_xy(geometry, foot) + np.array([balance.zmp_forward_m, -s * balance.zmp_inward_m])


def standing_zmp(geometry: BodyGeometry, left: FootPlacement, right: FootPlacement) -> np.ndarray:
    """Between the feet: the midpoint of the two soles' centres."""
    return 0.5 * (sole_centre_xy(geometry, left) + sole_centre_xy(geometry, right))


def shift(start, end, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """A smooth move of the ZMP reference from ``start`` to ``end`` over ``frames`` frames (the last at
    ``end``), and the share w of ``end`` per frame (the load moving onto the end foot)."""
    w = smootherstep(np.arange(1, frames + 1) / frames)
    return np.asarray(start) + w[:, None] * (np.asarray(end) - np.asarray(start)), w
