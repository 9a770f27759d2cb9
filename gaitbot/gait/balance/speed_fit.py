"""Fit the balanced walk to the servos' speed: relax double support, early progression and clearance
when a faster cycle or a longer step would ask a joint for more than its velocity limit.

Why: the swing leg is the fastest part of the plan and the servos cap it (the OP3's XM430-W350 turns
at most 276 deg/s unloaded). A robot's ``[balance]`` values are tuned for robustness at its own cycle
and step (on the OP3 a 15% double support, the progression done at 80% of the swing); at 0.2 m/s
(cycle 0.8 s, 8 cm steps) they would ask 434 deg/s. The swing speed scales as
1 / ((1 - double support) x progression_end) and its lift with the clearance, so the candidates are, in
order: the robot's values, then double support 10% / progression 0.9, then 5% / 1.0 / clearance 3 mm,
then the same 10 deg deeper in the crouch (the bent knee lifts and swings the foot with less speed);
the first whose steady walk at the longest step keeps every joint under its limit is used (the last
if none does: the limit check then says which joint, and when). One short offline plan per candidate.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.balance.walker import BalancedGaitSettings, generate_balanced_walk
from gaitbot.gait.body import BodyModel

FALLBACKS = ((0.10, 0.9, None, 0.0), (0.05, 1.0, 0.003, 0.0), (0.05, 1.0, 0.003, 10.0))
"""(double_support_share, progression_end, clearance_m, crouch deeper by deg), tried in order."""
PROBE_STEPS = 4


@dataclass(frozen=True)
class SpeedFit:
    """The settings to walk with, the planned peak joint speed (deg/s) against the limit, and which
    candidate was taken (0: the robot's own values)."""

    balance: BalanceSettings
    gait: BalancedGaitSettings
    peak_dps: float
    limit_dps: float
    relaxed: int

    @property
    def fits(self) -> bool:
        return self.peak_dps <= self.limit_dps


def peak_joint_speed_dps(q_rad, rate_hz: float) -> float:
    return float(np.degrees(np.abs(np.diff(q_rad, axis=0))).max() * rate_hz)


def fit_to_servo_speed(body: BodyModel, gait: BalancedGaitSettings, balance: BalanceSettings,
                       limit_dps: float) -> SpeedFit:
    """The first candidate whose steady walk at ``gait.max_step_m`` keeps every leg joint under ``limit_dps``."""
    candidates = [(balance, gait)]
    for ds, progression_end, clearance, deeper_deg in FALLBACKS:
        relaxed = replace(balance, double_support_share=min(balance.double_support_share, ds),
                          progression_end=max(balance.progression_end, progression_end),
                          crouch_knee_deg=balance.crouch_knee_deg + deeper_deg)
        candidates.append((relaxed, gait if clearance is None else replace(gait, clearance_m=min(gait.clearance_m,
                                                                                                  clearance))))
    fit = None
    for i, (b, g) in enumerate(candidates):
        walk = generate_balanced_walk(body, [g.max_step_m] * PROBE_STEPS, g, b)
        fit = SpeedFit(b, g, peak_joint_speed_dps(walk.q_rad, g.rate_hz), limit_dps, i)
        if fit.fits:
            break
    return fit
