"""Ramps in servo ticks: rest-to-rest between two poses (start ramp), and braking (safe stop).

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

__all__ = ["ramp_ticks", "brake_ticks", "stop_ticks"]


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
    accel = _accel_with_rounding_margin(max_accel_ticks_per_s2, period_s)

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


def _accel_with_rounding_margin(max_accel_ticks_per_s2: float, period_s: float) -> float:
    return max_accel_ticks_per_s2 - min(2.0 / period_s**2, max_accel_ticks_per_s2 / 2)


def brake_ticks(previous_ticks: ArrayLike, last_ticks: ArrayLike, max_accel_ticks_per_s2: float,
                period_s: float) -> np.ndarray:
    """Frames (M, J) bringing every joint from its current velocity to rest at the acceleration limit.

    The velocity is taken from the last two frames sent, one period apart. Each joint brakes
    on its own at full deceleration. Joints are not synchronised here, because the shortest
    stop is what matters: it overshoots the last pose by v^2 / (2 a). A trajectory that keeps
    within its joint limits under the same acceleration limit always has that much room,
    since it must itself be able to stop before a limit it is moving towards. (The
    rounding margin makes the planned deceleration a little lower than ``max_accel``, so the
    overshoot is a little longer: v^2 / (2 (a - 2 ticks/period^2)).)
    Empty when no joint is moving, or none moves a whole tick while stopping.
    """
    previous = np.rint(np.asarray(previous_ticks, dtype=np.float64).reshape(-1))
    last = np.rint(np.asarray(last_ticks, dtype=np.float64).reshape(-1))
    if previous.shape != last.shape:
        raise ValueError(f"previous_ticks has {previous.size} joints but last_ticks has {last.size}")
    if not (max_accel_ticks_per_s2 > 0 and period_s > 0):
        raise ValueError(f"max_accel_ticks_per_s2 and period_s must be > 0, got {max_accel_ticks_per_s2}, {period_s}")
    velocity = (last - previous) / period_s
    accel = _accel_with_rounding_margin(max_accel_ticks_per_s2, period_s)
    stop_time_s = np.abs(velocity) / accel
    longest_s = float(np.max(stop_time_s, initial=0.0))
    if longest_s == 0.0:
        return np.empty((0, last.size), dtype=np.int64)
    count = max(1, math.ceil(longest_s / period_s - 1e-9))
    t = np.minimum(np.arange(1, count + 1)[:, None] * period_s, stop_time_s[None, :])
    position = last + velocity * t - 0.5 * np.sign(velocity) * accel * t**2
    frames = np.rint(position).astype(np.int64)
    if (frames == last).all():
        return np.empty((0, last.size), dtype=np.int64)  # the stop is shorter than a tick: nothing to send
    return frames


def stop_ticks(previous_ticks: ArrayLike, last_ticks: ArrayLike, stand_ticks: ArrayLike,
               max_velocity_ticks_per_s: float, max_accel_ticks_per_s2: float, period_s: float) -> np.ndarray:
    """The safe stop: brake from the current motion, then ramp at rest to ``stand_ticks``.

    Acceleration stays within the limit from the motion already under way (the last two
    frames) through to standing, which a ramp starting "from rest" at the last pose would
    not do: a joint moving at v would be stopped within one frame, at v / period.
    """
    brake = brake_ticks(previous_ticks, last_ticks, max_accel_ticks_per_s2, period_s)
    rest = brake[-1] if len(brake) else np.rint(np.asarray(last_ticks, dtype=np.float64)).reshape(-1)
    ramp = ramp_ticks(rest, stand_ticks, max_velocity_ticks_per_s, max_accel_ticks_per_s2, period_s)
    return np.concatenate([brake, ramp]) if len(brake) else ramp
