"""The check ``gaitbot walk`` runs before anything moves: the same code as ``gaitbot check``.

Joint limits (check/trajectory.py), balance (check/balance.py) and the feet's clearance from each other
(check/feet.py): a walk that would tip the robot or make its feet touch is refused like one that breaks a
limit, unless the robot walks on a boom.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from gaitbot.check.balance import CONTACT_TOL_M, balance_trace, tipping_direction
from gaitbot.check.feet import feet_episodes, feet_margin_m, sole_gaps_m
from gaitbot.check.trajectory import BalanceSummary, CheckReport, Violation, check_trajectory, trajectory_angles_deg
from gaitbot.errors import UserError
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import RobotConfig


class LimitBroken(UserError):
    """A walk breaks a limit of the robot (or would tip it over): refused before anything moves, in one line.
    The check failed, as ``gaitbot check`` fails on the same file: exit 1 (docs/command-line.md), not 2 (the
    input is readable). ``gaitbot generate`` raises it too, after writing the walk ``gaitbot walk`` would refuse."""

    exit_status = 1


class TrajectoryMismatch(UserError, ValueError):
    """A trajectory moves a joint the robot does not have, or one it holds: one line, exit 2."""


def robot_angles_deg(config: RobotConfig, trajectory: Trajectory):
    """(N, n_joints) degrees of every joint of ``config`` for ``trajectory``, its joints placed by name:
    moving joints the trajectory lacks stay at 0 (a planar walk keeps roll and yaw straight)."""
    try:
        return trajectory_angles_deg(config, trajectory.angles_rad, trajectory.joints)
    except ValueError as exc:
        raise TrajectoryMismatch(f"the trajectory does not fit robot {config.name}: {exc}") from None


def preflight(config: RobotConfig, trajectory: Trajectory, margin_deg: float = 0.0, *,
              on_boom: bool = False, planned: Trajectory | None = None) -> CheckReport:
    """Every frame of ``trajectory`` (what the servos are sent) against ``config``'s limits (held joints at
    their hold angles) and, unless the robot walks on a boom (``on_boom`` or ``[robot] boom``), the body's
    motion against tipping over: ``planned`` if given, else ``trajectory``. The two differ when a
    balanced walk's goals carry the servo-sag feedforward: the goals overshoot by the sag the loaded servos
    will have (docs/balance.md), so the body follows the planned angles, not the goals."""
    angles = robot_angles_deg(config, trajectory)
    report = check_trajectory(config, trajectory.t_s, angles, margin_deg)
    if on_boom or config.boom:
        why = "[robot] boom = true" if config.boom else "--boom"
        return replace(report, balance=BalanceSummary(False, f"{config.name} walks on a boom: {why}"))
    if planned is not None:
        trajectory, angles = planned, robot_angles_deg(config, planned)
    trace = balance_trace(config, trajectory, angles)
    outside = trace.margin_m < 0
    found = _balance_episodes(trace, outside) + _sinking_episodes(trace)
    gaps = sole_gaps_m(trace.soles)  # the feet's clearance from each other (check/feet.py)
    found += feet_episodes(trace.t_s, gaps, feet_margin_m(config))
    supported = np.isfinite(trace.margin_m)
    k = int(np.argmin(np.where(supported, trace.margin_m, np.inf))) if supported.any() else 0
    g = int(np.argmin(gaps))
    summary = BalanceSummary(True, "", float(1e3 * trace.margin_m[k]) if supported.any() else 0.0,
                             float(trace.t_s[k]), int(outside.sum()),
                             tuple(float(v) for v in trace.com_m[-1, :2] - trace.com_m[0, :2]),
                             int((~supported).sum()), float(1e3 * gaps[g]), float(trace.t_s[g]))
    violations = tuple(sorted(report.violations + tuple(found), key=lambda v: v.t_s))
    return replace(report, violations=violations, balance=summary)


def _sinking_episodes(trace) -> list[Violation]:
    """Soles below the floor: a trajectory whose root is not where its feet say (e.g. the hip point given
    for a robot whose root lies above its hips) cannot be judged for balance; say so."""
    lowest = np.minimum(trace.soles["left"][:, :, 2].min(axis=1), trace.soles["right"][:, :, 2].min(axis=1))
    below = lowest < -CONTACT_TOL_M
    if not below.any():
        return []
    k = int(np.argmin(lowest))
    frames = np.flatnonzero(below)
    return [Violation(kind="balance", joint="support", t_s=float(trace.t_s[k]), value=-1e3 * float(lowest[k]),
                      limit=0.0, severity="error", limit_name="below the floor", t_start_s=float(trace.t_s[frames[0]]),
                      t_end_s=float(trace.t_s[frames[-1]]), n_samples=int(below.sum()))]


def _balance_episodes(trace, outside: np.ndarray) -> list[Violation]:
    """One violation per run of frames whose ZMP is outside the support polygon (the worst frame of each)."""
    out = []
    k = 0
    n = len(outside)
    while k < n:
        if not outside[k]:
            k += 1
            continue
        end = k
        while end + 1 < n and outside[end + 1]:
            end += 1
        worst = k + int(np.argmin(trace.margin_m[k:end + 1]))
        if np.isfinite(trace.margin_m[worst]):
            joint, depth_mm = "zmp", -1e3 * float(trace.margin_m[worst])
            direction = tipping_direction(trace.zmp_m[worst], trace.support[worst])
        else:
            joint, depth_mm, direction = "support", 0.0, "no sole on the ground"
        out.append(Violation(kind="balance", joint=joint, t_s=float(trace.t_s[worst]), value=depth_mm, limit=0.0,
                             severity="error", limit_name=direction, t_start_s=float(trace.t_s[k]),
                             t_end_s=float(trace.t_s[end]), n_samples=end - k + 1))
        k = end + 1
    return out
