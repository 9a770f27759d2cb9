"""A planar walk fitted to the servos' limits with the planning margin: a longer cycle where one is needed.

A pitch-only robot walks with Boulic's walker (gaitbot.gait.walker), whose joint speeds scale about with
1 / cycle and accelerations with 1 / cycle^2. A walk whose goals would ask a joint for more than
PLANNED_SHARE (gaitbot.robot.motion_margin) of its max_velocity_dps or max_acceleration_dps2, measured
as the servos see them (gaitbot.robot.joint_motion), is planned again with its cycle stretched by what
that scaling says, until it fits (a few tries; each plans the whole walk, a few ms).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from gaitbot.gait.trajectory import Trajectory
from gaitbot.gait.walker import WalkSettings
from gaitbot.robot.calibration import full_angles_rad
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.joint_motion import limit_shares, peak_share
from gaitbot.robot.motion_margin import PLANNED_SHARE

TRIES = 6
"""Plans tried at most (the first at the asked cycle)."""


def trajectory_share(config: RobotConfig, trajectory: Trajectory) -> tuple[float, float, str]:
    """(peak velocity share, peak acceleration share, which joint and how much) of a trajectory's motion
    against ``config``'s limits, as the servos see it (held joints at their hold angles)."""
    angles = np.degrees(full_angles_rad(config, trajectory.angles_rad, trajectory.joints))
    v, a = limit_shares(config, trajectory.t_s, angles)
    return float(v.max()), float(a.max()), peak_share(config, trajectory.t_s, angles)[1]


@dataclass(frozen=True)
class CycleFit:
    """The walk planned (``plan``, and its ``trajectory``), the cycle asked for and the one walked, and the
    walk's largest share of a limit (``share``, ``worst`` says which joint) against PLANNED_SHARE."""

    plan: object
    trajectory: Trajectory
    asked_cycle_s: float
    cycle_s: float
    share: float
    worst: str

    @property
    def stretched(self) -> bool:
        return self.cycle_s > self.asked_cycle_s

    @property
    def fits(self) -> bool:
        return self.share <= PLANNED_SHARE

    def note(self) -> str | None:
        """One line when the cycle was stretched or the walk does not keep the margin, else None."""
        if self.stretched and self.fits:
            return (f"the servos' limits (kept within {100 * PLANNED_SHARE:g}%) needed a longer cycle at this step: "
                    f"{self.cycle_s:.3g} s instead of {self.asked_cycle_s:.3g} s (peak {self.worst}; "
                    f"docs/checking.md)")
        if not self.fits:
            return (f"the walk asks {100 * self.share:.1f}% of a servo's limit ({self.worst}), more than the "
                    f"{100 * PLANNED_SHARE:g}% planned walks keep (a longer --cycle or shorter steps fit; "
                    f"docs/checking.md)")
        return None


def fit_cycle(config: RobotConfig | None, settings: WalkSettings,
              plan: Callable[[WalkSettings], tuple[object, Trajectory]]) -> CycleFit:
    """``plan(settings) -> (plan, trajectory)`` at the asked cycle, then at longer ones until the trajectory
    keeps PLANNED_SHARE of ``config``'s limits (no robot: no limits, planned once)."""
    asked = settings.cycle_s
    walk, trajectory = plan(settings)
    if config is None:
        return CycleFit(walk, trajectory, asked, asked, 0.0, "")
    cycle = asked
    for k in range(TRIES):
        v, a, worst = trajectory_share(config, trajectory)
        if max(v, a) <= PLANNED_SHARE or k == TRIES - 1:
            break
        longer = cycle * max(v / PLANNED_SHARE, math.sqrt(a / PLANNED_SHARE), 1.0) * 1.01
        try:
            walk, trajectory = plan(replace(settings, cycle_s=longer))
        except (ValueError, ArithmeticError):
            break  # the walker cannot walk this cycle: keep the last plan (the check says what it breaks)
        cycle = longer
    return CycleFit(walk, trajectory, asked, cycle, max(v, a), worst)
