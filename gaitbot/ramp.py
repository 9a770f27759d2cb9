"""Rest-to-rest ramps between two poses in servo ticks: the start ramp and the safe stop.

Pure numpy, no I/O. All joints move together on one normalised trapezoidal velocity
profile (constant acceleration, cruise, constant deceleration), so they leave and
arrive on the same frame and the joint with the longest way to go sets the duration.

Limits hold at frame resolution on the integer frames actually sent. A sampled trapezoid
already meets them: the first difference of samples is the mean velocity over a period and
the second difference is a weighted mean of acceleration. Rounding each sample to a
whole tick, though, can add up to 1 tick per period of velocity and 2 ticks per period^2
of acceleration. So the profile is planned with those margins subtracted and the rounded
frames stay within the caller's limits. When a limit is so low that the margin would
use up more than half of it (below 2 ticks/period, or 4 ticks/period^2), the margin is
capped at half the limit. The frames then keep within the limit plus at most one tick of
quantisation, which no integer trajectory can avoid at that rate.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["ramp_ticks"]


def ramp_ticks(from_ticks: ArrayLike, to_ticks: ArrayLike, max_velocity_ticks_per_s: float,
               max_accel_ticks_per_s2: float, period_s: float) -> np.ndarray:
    """Frames (M, J) of int64 ticks taking every joint from ``from_ticks`` to ``to_ticks``.

    Frame k is the pose at time (k + 1) * period_s after leaving ``from_ticks`` (at rest);
    the last frame is exactly ``to_ticks``. If no joint is more than 1 tick away, the
    ramp is empty (shape (0, J)): a one-tick difference is within the servo's own
    resolution and not worth a motion.
    """
    start = np.asarray(from_ticks, dtype=np.float64).reshape(-1)
    target = np.asarray(to_ticks, dtype=np.float64).reshape(-1)
    if start.shape != target.shape:
        raise ValueError(f"from_ticks has {start.size} joints but to_ticks has {target.size}")
    if not (max_velocity_ticks_per_s > 0 and max_accel_ticks_per_s2 > 0 and period_s > 0):
        raise ValueError("max_velocity_ticks_per_s, max_accel_ticks_per_s2 and period_s must be > 0 "
                         f"(got {max_velocity_ticks_per_s}, {max_accel_ticks_per_s2}, {period_s})")
    if not (np.all(np.isfinite(start)) and np.all(np.isfinite(target))):
        raise ValueError("from_ticks and to_ticks must be finite")
    start, target = np.rint(start), np.rint(target)
    delta = target - start
    distance = float(np.max(np.abs(delta), initial=0.0))
    if distance <= 1.0:
        return np.empty((0, start.size), dtype=np.int64)

    # Margins for rounding to whole ticks (see module docstring), capped at half the limit.
    velocity = max_velocity_ticks_per_s - min(1.0 / period_s, max_velocity_ticks_per_s / 2)
    accel = max_accel_ticks_per_s2 - min(2.0 / period_s**2, max_accel_ticks_per_s2 / 2)

    progress = _trapezoid_progress(distance, velocity, accel, period_s)
    frames = np.rint(start + progress[:, None] * delta[None, :]).astype(np.int64)
    frames[-1] = target.astype(np.int64)
    return frames


def _trapezoid_progress(distance: float, velocity: float, accel: float, period_s: float) -> np.ndarray:
    """Fraction of the way covered (0..1] at t = period_s, 2 period_s, ..., until arrival.

    Rest-to-rest minimum-time profile for one axis with |v| <= velocity, |a| <= accel:
    a trapezoid if the distance allows reaching ``velocity``, else a triangle.
    """
    if distance * accel >= velocity**2:
        accel_time_s = velocity / accel
        total_s = distance / velocity + accel_time_s
    else:
        accel_time_s = math.sqrt(distance / accel)
        velocity = accel * accel_time_s
        total_s = 2 * accel_time_s
    count = max(1, math.ceil(total_s / period_s - 1e-9))
    t = np.minimum(np.arange(1, count + 1) * period_s, total_s)
    position = np.where(
        t < accel_time_s,
        0.5 * accel * t**2,
        np.where(t <= total_s - accel_time_s,
                 0.5 * accel * accel_time_s**2 + velocity * (t - accel_time_s),
                 distance - 0.5 * accel * (total_s - t) ** 2),
    )
    progress = np.clip(position / distance, 0.0, 1.0)
    progress[-1] = 1.0
    return progress
