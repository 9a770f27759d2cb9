"""The drive's own check of every frame before it is sent: joint limits, velocity and acceleration.

Preflight cannot see a live walk's future, so each frame the walker computes is checked here, in angles
(no tick rounding), against the same joint limits ``gaitbot check`` uses: position (min/max_deg),
velocity (max_velocity_dps) and acceleration (max_acceleration_dps2) from the two frames before it. A frame
outside that window by a hair (CLIP_SHARE of a frame's largest step) is brought to its edge (``admit``); a
frame that fails by more is never sent: the drive replaces the rest of the walk by the session's stop ramp
from the last frame that passed (gaitbot.stream.ramps.stop_ticks, itself within the limits).
"""

from __future__ import annotations

import math

import numpy as np

from gaitbot.gait.joints import LEG_JOINTS

RATE_SLACK = 1.0 + 1e-6  # float noise only: a frame is refused at the limit itself
CLIP_SHARE = 0.02
"""``admit``: a frame outside the window its limits allow by at most this share of the joint's largest step in
one frame (max velocity x period: 0.1 deg for a 300 deg/s servo at 60 Hz) is brought to the window's edge."""


class FrameGuard:
    """Checks goal angles (LEG_JOINTS order, rad) frame by frame; ``check`` returns a reason or None."""

    def __init__(self, config, period_s: float) -> None:
        joints = {j.name: j for j in config.joints}
        chosen = [joints[name] for name in LEG_JOINTS]
        self.lower = np.radians([j.hold_deg if j.hold_deg is not None else j.min_deg for j in chosen])
        self.upper = np.radians([j.hold_deg if j.hold_deg is not None else j.max_deg for j in chosen])
        self.max_velocity = np.radians([j.max_velocity_dps for j in chosen]) * RATE_SLACK
        self.max_accel = np.radians([j.max_acceleration_dps2 for j in chosen]) * RATE_SLACK
        self.period_s = period_s
        self.previous: np.ndarray | None = None
        self.velocity: np.ndarray | None = None
        self.clipped = 0

    def reset(self, q_rad) -> None:
        """The robot stands still at ``q_rad`` (between two walks)."""
        self.previous = np.asarray(q_rad, dtype=float)
        self.velocity = np.zeros_like(self.previous)

    def admit(self, q_rad) -> tuple[np.ndarray | None, str | None]:
        """(the frame to send, None), or (None, why not). A frame outside what its joints' limits allow after the
        frames before it (position, velocity, acceleration) by a hair (CLIP_SHARE of a frame's largest step:
        the walker's rounding at a limit) is brought inside, to the nearest allowed angle; anything more is
        refused. ``clipped`` counts the frames brought inside."""
        q = np.asarray(q_rad, dtype=float)
        if self.previous is not None and self.velocity is not None:
            dt = self.period_s
            step = self.max_velocity * dt / RATE_SLACK
            change = self.max_accel * dt * dt / RATE_SLACK
            low = np.maximum(self.lower, np.maximum(self.previous - step, self.previous + self.velocity * dt - change))
            high = np.minimum(self.upper, np.minimum(self.previous + step, self.previous + self.velocity * dt + change))
            outside = np.maximum(low - q, q - high)
            if (low <= high).all() and (outside > 0).any() and (outside <= CLIP_SHARE * step).all():
                q = np.clip(q, low, high)
                self.clipped += 1
        reason = self.check(q)
        return (None, reason) if reason is not None else (q, None)

    def check(self, q_rad) -> str | None:
        """None if the frame may be sent (and it becomes the previous frame), else why not."""
        q = np.asarray(q_rad, dtype=float)
        bad = np.flatnonzero((q < self.lower - 1e-9) | (q > self.upper + 1e-9))
        if bad.size:
            j = bad[0]
            return (f"{LEG_JOINTS[j]} would go to {math.degrees(q[j]):.1f} deg, outside "
                    f"{math.degrees(self.lower[j]):.1f}..{math.degrees(self.upper[j]):.1f} deg")
        if self.previous is not None:
            velocity = (q - self.previous) / self.period_s
            fast = np.flatnonzero(np.abs(velocity) > self.max_velocity)
            if fast.size:
                j = fast[0]
                return (f"{LEG_JOINTS[j]} would move at {math.degrees(abs(velocity[j])):.0f} deg/s, over its "
                        f"{math.degrees(self.max_velocity[j]):.0f} deg/s")
            if self.velocity is not None:
                accel = (velocity - self.velocity) / self.period_s
                hard = np.flatnonzero(np.abs(accel) > self.max_accel)
                if hard.size:
                    j = hard[0]
                    return (f"{LEG_JOINTS[j]} would accelerate at {math.degrees(abs(accel[j])):.0f} deg/s^2, over "
                            f"its {math.degrees(self.max_accel[j]):.0f} deg/s^2")
            self.velocity = velocity
        self.previous = q
        return None
