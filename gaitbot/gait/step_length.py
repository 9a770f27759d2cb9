"""Step length of the Boulic model and its inverse (Jing et al. 2015 sections 2.3 and 4 of docs/gait-model.md).

The realised step length is the distance between consecutive heel-strike points in the world.
With the supporting foot rolling heel-then-toe without slipping, it follows exactly from the
pose at heel strike: the rear foot's rolling anchor (its heel point when flat) is fixed in the
world, so SL = front heel x - rear anchor x, both measured in the body frame at that instant.
This replaces the paper's approximation SL' (eq. 10) and its linear correction (eq. 11).

Lengths here are in the geometry's own unit; divide by ``geometry.leg_length`` to normalise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.errors import UserError

from .blend import BoulicBlend
from .boulic import REGION_A_MAX, TABLE2_CYCLE_S, pose_rad
from .geometry import LegGeometry, foot_pitch, leg_points


class StepLengthError(UserError, ValueError):
    """A requested step length is negative, not finite, or beyond the reachable maximum."""


def rolling_anchor_x(geometry: LegGeometry, heel_x, toe_x, pitch):
    """World (or body) x of the foot's rolling anchor: its heel point when the sole is flat.

    A foot on the ground rests on its lower point: the heel while the toe is up (pitch >= 0), the
    toe while the toe is down. Rolling without slip keeps that point fixed, so the anchor is the
    heel x itself, or the toe x less the sole length.
    """
    return np.where(np.asarray(pitch) >= 0.0, heel_x, np.asarray(toe_x) - geometry.foot)


def boulic_step_length(geometry: LegGeometry, rv, cycle_s: float = TABLE2_CYCLE_S):
    """Realised step length of the Boulic model at RV (array or scalar), in geometry units.

    At heel strike (phase 0) the left leg is in front at its phase 0, the right behind at 0.5.
    Vectorised over RV (BoulicBlend's region-A form: one RV per sample at fixed phases).
    """
    rv = np.atleast_1d(np.asarray(rv, dtype=float))
    blend = BoulicBlend([0.0, REGION_A_MAX], cycle_s)
    if np.all(rv <= REGION_A_MAX):
        u = rv / REGION_A_MAX  # degree-1 Bernstein weights (1 - u, u) give RV = u * 0.5 exactly
        front = blend.leg(np.zeros_like(rv), u)
        rear = blend.leg(np.full_like(rv, 0.5), u)
    else:
        front = np.array([pose_rad(float(r), 0.0, cycle_s)[:3] for r in rv])
        rear = np.array([pose_rad(float(r), 0.0, cycle_s)[3:] for r in rv])
    _, _, heel_front, _ = leg_points(geometry, *front.T)
    _, _, heel_rear, toe_rear = leg_points(geometry, *rear.T)
    anchor = rolling_anchor_x(geometry, heel_rear[:, 0], toe_rear[:, 0], foot_pitch(*rear.T))
    return heel_front[:, 0] - anchor


def step_length_to_rv_bisection(geometry: LegGeometry, step_length: float, tolerance: float = 0.01,
                                cycle_s: float = TABLE2_CYCLE_S, max_iterations: int = 200) -> tuple[float, int]:
    """Jing et al.'s Algorithm 1: bisect RV on [0, 0.5] until |SL - SL*| <= tolerance (geometry units).

    Kept as the reference the fast inverse is tested against. Returns (rv, iterations).
    """
    low, high = 0.0, REGION_A_MAX
    rv = 0.5 * (low + high)
    sl = float(boulic_step_length(geometry, rv, cycle_s)[0])
    iterations = 1
    while abs(sl - step_length) > tolerance and iterations < max_iterations:
        if sl > step_length:
            high = rv
        else:
            low = rv
        rv = 0.5 * (low + high)
        sl = float(boulic_step_length(geometry, rv, cycle_s)[0])
        iterations += 1
    return rv, iterations


@dataclass(frozen=True)
class StepLengthInverse:
    """Fast, tight inverse of SL(RV) over region A: a monotone table plus safeguarded secant steps.

    Build once per geometry and cycle (``StepLengthInverse.build``); ``rv(sl)`` then costs a
    table lookup and two or three exact SL evaluations to reach ``tolerance`` (default 1e-12
    leg lengths). SL rises monotonically with RV in region A (Jing et al. 2015, Appendix B); the build
    checks that on its grid for the given geometry and refuses a geometry where it fails.
    """

    geometry: LegGeometry
    cycle_s: float
    rv_grid: np.ndarray
    sl_grid: np.ndarray
    rv_at_zero: float  # RV whose step length is 0 (0.0 if SL(0) > 0 for this leg)
    max_step_length: float
    tolerance: float

    @classmethod
    def build(cls, geometry: LegGeometry, cycle_s: float = TABLE2_CYCLE_S, grid_points: int = 201,
              tolerance_leg_lengths: float = 1e-12) -> "StepLengthInverse":
        rv_grid = np.linspace(0.0, REGION_A_MAX, grid_points)
        sl_grid = boulic_step_length(geometry, rv_grid, cycle_s)
        if np.any(np.diff(sl_grid) <= 0):
            bad = rv_grid[int(np.argmax(np.diff(sl_grid) <= 0))]
            raise ValueError(f"step length does not rise with RV near RV={bad:.3f} for this leg geometry; "
                             "check thigh, shank and foot lengths")
        tolerance = tolerance_leg_lengths * geometry.leg_length
        inverse = cls(geometry, cycle_s, rv_grid, sl_grid, 0.0, float(sl_grid[-1]), tolerance)
        if sl_grid[0] < 0.0:
            object.__setattr__(inverse, "rv_at_zero", inverse._solve(0.0))
        return inverse

    @property
    def reachable_range(self) -> tuple[float, float]:
        """Step lengths (geometry units) the model can take: from 0 to SL at the top of region A."""
        return 0.0, self.max_step_length

    def validate(self, step_length: float, what: str = "step length") -> float:
        """Return ``step_length`` as a float, or raise StepLengthError saying what is allowed."""
        try:
            value = float(step_length)
        except (TypeError, ValueError):
            raise StepLengthError(f"{what} {step_length!r} is not a number") from None
        if not math.isfinite(value):
            raise StepLengthError(f"{what} {step_length!r} is not a finite number")
        if value < 0.0:
            raise StepLengthError(f"{what} {value:g} is negative; allowed 0 to {self.max_step_length:.4g}")
        if value > self.max_step_length * (1 + 1e-12):
            raise StepLengthError(f"{what} {value:g} is longer than the reachable maximum "
                                  f"{self.max_step_length:.4g} (Boulic region A, RV < 0.5, for this leg)")
        return min(value, self.max_step_length)

    def rv(self, step_length: float) -> float:
        """RV whose realised step length is ``step_length`` to within ``tolerance``.

        Step lengths below SL(RV=0) (possible only for legs where SL(0) > 0) map to RV = 0.
        """
        value = self.validate(step_length)
        cache = self._cache
        if value not in cache:
            if len(cache) > 4096:
                cache.clear()
            cache[value] = 0.0 if value <= self.sl_grid[0] and self.sl_grid[0] >= 0.0 else self._solve(value)
        return cache[value]

    @property
    def _cache(self) -> dict:
        try:
            return self.__dict__["_rv_cache"]
        except KeyError:
            self.__dict__["_rv_cache"] = {}
            return self.__dict__["_rv_cache"]

    def _step_length(self, rv: float) -> float:
        """SL at one region-A RV in closed form: the heel-strike pose is affine in RV there."""
        try:
            front0, front1, rear0, rear1 = self.__dict__["_affine_pose"]
        except KeyError:
            ends = np.array([0.0, REGION_A_MAX])
            blend = BoulicBlend(ends, self.cycle_s)
            front = blend.leg(np.zeros(2), np.array([0.0, 1.0]))
            rear = blend.leg(np.full(2, 0.5), np.array([0.0, 1.0]))
            front0, front1 = front[0], (front[1] - front[0]) / REGION_A_MAX
            rear0, rear1 = rear[0], (rear[1] - rear[0]) / REGION_A_MAX
            self.__dict__["_affine_pose"] = (front0, front1, rear0, rear1)
        g = self.geometry
        hf, kf, af = front0 + front1 * rv
        hr, kr, ar = rear0 + rear1 * rv
        # heel of each foot relative to the hip: ankle, then ankle_height down the sole normal, heel_back along it
        def heel_x(h, k, a):
            pitch = h - k + a
            ankle = g.thigh * math.sin(h) + g.shank * math.sin(h - k)
            return ankle + g.ankle_height * math.sin(pitch) - g.heel_back * math.cos(pitch), pitch
        front_heel, _ = heel_x(hf, kf, af)
        rear_heel, rear_pitch = heel_x(hr, kr, ar)
        if rear_pitch >= 0.0:
            return front_heel - rear_heel
        toe = rear_heel + g.foot * math.cos(rear_pitch)
        return front_heel - (toe - g.foot)

    def _solve(self, target: float) -> float:
        i = int(np.clip(np.searchsorted(self.sl_grid, target) - 1, 0, len(self.rv_grid) - 2))
        lo_rv, hi_rv = float(self.rv_grid[i]), float(self.rv_grid[i + 1])
        lo_sl, hi_sl = float(self.sl_grid[i]) - target, float(self.sl_grid[i + 1]) - target
        rv = lo_rv
        for _ in range(60):
            # secant (regula falsi, Illinois-free since the bracket is tiny and SL is smooth) then bisection guard
            rv = lo_rv - lo_sl * (hi_rv - lo_rv) / (hi_sl - lo_sl) if hi_sl != lo_sl else 0.5 * (lo_rv + hi_rv)
            if not lo_rv < rv < hi_rv:
                rv = 0.5 * (lo_rv + hi_rv)
            err = self._step_length(rv) - target
            if abs(err) <= self.tolerance:
                return rv
            if err < 0:
                lo_rv, lo_sl = rv, err
            else:
                hi_rv, hi_sl = rv, err
        return rv
