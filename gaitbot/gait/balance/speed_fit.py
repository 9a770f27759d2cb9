"""Fit the balanced walk to the servos' speed: relax double support, early progression and clearance
when a faster cycle or a longer step would ask a joint for more than its velocity limit.

Why: the swing leg is the fastest part of the plan and the servos cap it (the OP3's XM430-W350 turns
at most 276 deg/s unloaded). A robot's ``[balance]`` values are tuned for robustness at its own cycle
and step (on the OP3 a 15% double support, the progression done at 80% of the swing); at 0.2 m/s
(cycle 0.8 s, 8 cm steps) they would ask 434 deg/s. The swing speed scales as
1 / ((1 - double support) x progression_end) and its lift with the clearance, so the candidates are, in
order: the robot's values; the same 10 deg deeper in the crouch (the bent knee lifts and swings the foot
with less speed); double support 10% / progression 0.9; 5% / 0.9 / clearance 3 mm, then 10 deg deeper;
5% / 1.0 / 3 mm, then 10 deg deeper (FALLBACKS); a clearance the user asked for is kept (the fallbacks then
relax the rest only). The first whose walk keeps every joint at or under ``share``
of its limits (the robot's planners keep PLANNED_SHARE, gaitbot.robot.motion_margin, measured by
gaitbot.robot.joint_motion: velocity and acceleration of the goal ticks as sent) is used; if none does, the
one that asks the least share of a limit, the earlier of equals (the limit check then says whether it is
still within the limits, which joint, and when). The walk itself is planned for each candidate until one
fits (an offline walk of 2 m takes ~0.1 s).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.balance.walker import (BalancedGaitSettings, BalancedWalk, BalancedWalker, BalancedWalkError,
                                         plan_balanced_walk, walk_of)
from gaitbot.gait.body import BodyModel

FALLBACKS = ((1.0, 0.0, None, 10.0), (0.10, 0.9, None, 0.0), (0.05, 0.9, 0.003, 0.0), (0.05, 0.9, 0.003, 10.0),
             (0.05, 1.0, 0.003, 0.0), (0.05, 1.0, 0.003, 10.0))
"""(double_support_share, progression_end, clearance_m, crouch deeper by deg), tried in order. The progression done
at 100% of the swing comes last: a foot still moving forward when it lands lands short (at the shipped cycle
89% of the plan's step, against 96% for the 3 mm clearance; python tools/fast_walks.py, docs/walk-faster.md)."""
PROBE_STEPS = 4


@dataclass(frozen=True, eq=False)
class SpeedFit:
    """The settings walked with, the walk's peak joint speed (deg/s, planned angles or goals) against the
    limit, which candidate was taken (0: the robot's own values), and the walk (with its walker).
    ``peak_share``: the largest share of a joint's velocity or acceleration limit the walk reaches (planned
    angles or goals), against ``target_share``, the share the fit keeps to."""

    balance: BalanceSettings
    gait: BalancedGaitSettings
    peak_dps: float
    limit_dps: float
    relaxed: int
    walk: BalancedWalk | None = None
    walker: BalancedWalker | None = None
    peak_share: float = float("nan")
    target_share: float = 1.0

    @property
    def fits(self) -> bool:
        return self.peak_share <= self.target_share

    @property
    def kept_clearance(self) -> bool:
        """The candidate taken would have lowered the clearance, and kept the one the user asked for instead."""
        lowered = FALLBACKS[self.relaxed - 1][2] if self.relaxed else None
        return self.gait.clearance_asked and lowered is not None and lowered < self.gait.clearance_m


def peak_joint_speed_dps(q_rad, rate_hz: float) -> float:
    return float(np.degrees(np.abs(np.diff(q_rad, axis=0))).max() * rate_hz)


def candidates(gait: BalancedGaitSettings, balance: BalanceSettings):
    """The robot's own settings, then FALLBACKS relaxed from them."""
    out = [(balance, gait)]
    for ds, progression_end, clearance, deeper_deg in FALLBACKS:
        relaxed = replace(balance, double_support_share=min(balance.double_support_share, ds),
                          progression_end=max(balance.progression_end, progression_end),
                          crouch_knee_deg=balance.crouch_knee_deg + deeper_deg)
        lowered = clearance is not None and not gait.clearance_asked
        out.append((relaxed, replace(gait, clearance_m=min(gait.clearance_m, clearance)) if lowered else gait))
    return out


def fit_to_servo_speed(body: BodyModel, gait: BalancedGaitSettings, balance: BalanceSettings, limit_dps: float,
                       steps=None, *, measure=None, share: float = 1.0, first: int = 0, **options) -> SpeedFit:
    """The first candidate whose walk (``steps``; default a steady walk at ``gait.max_step_m``) keeps every
    leg joint's planned angle and goal at or under ``share`` of its limits; ``options`` go to the walker
    (limits, stiffness). ``measure(q_rad, rate_hz) -> (share of the limits, peak deg/s)`` of (N, 12) leg
    angles measures a walk (default: the peak speed over ``limit_dps``, gaitbot.robot.balanced_walk gives the
    robot's, gaitbot.robot.joint_motion). Candidates are tried from index ``first`` on (a walk of one family
    starts where its steady walk's fit ended). A candidate the joint limits refuse is skipped; if every one
    is refused, the first refusal is raised."""
    if measure is None:
        def measure(q_rad, rate_hz):
            peak_dps = peak_joint_speed_dps(q_rad, rate_hz)
            return peak_dps / limit_dps, peak_dps

    steps = [gait.max_step_m] * PROBE_STEPS if steps is None else list(steps)
    fit, best, refused = None, None, None
    for i, (b, g) in list(enumerate(candidates(gait, balance)))[first:]:
        try:
            walker = plan_balanced_walk(body, steps, g, b, **options)
            walk = walk_of(walker)
        except BalancedWalkError as exc:
            refused = refused or exc
            continue
        (share_q, peak_q), (share_goals, peak_goals) = measure(walk.q_rad, g.rate_hz), measure(walk.goals_rad, g.rate_hz)
        fit = SpeedFit(b, g, max(peak_q, peak_goals), limit_dps, i, walk, walker, max(share_q, share_goals), share)
        if fit.fits:
            return fit
        if best is None or fit.peak_share < best.peak_share:
            best = fit
    if best is None:
        raise refused
    return best
