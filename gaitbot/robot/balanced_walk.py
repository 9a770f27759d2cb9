"""From a robot config to the balanced walker (gaitbot.gait.balance) for robots whose legs roll.

A robot with hip and ankle roll joints (``config.is_3d``) walks with the balanced walker: its body model
(``[links.*]``), ``[balance]`` settings, ``[gait]`` cycle, rate, longest step and clearance, its joint
limits, and the stiffness its servos are given (``[servo] full_torque_error_deg`` written to them, else
their factory gain) for the sag feedforward. Pitch-only robots keep the planar Boulic walker
(gaitbot.gait.walker, via walk_settings.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gaitbot.gait.balance.speed_fit import SpeedFit, fit_to_servo_speed
from gaitbot.gait.balance.walker import (BalancedGaitSettings, BalancedWalk, BalancedWalker, BalancedWalkError,
                                         walk_of, plan_balanced_walk)
from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.calibration import full_angles_rad
from gaitbot.robot.gains import gain_for_error
from gaitbot.robot.joint_motion import as_sent_deg, joint_motion, limit_shares
from gaitbot.robot.motion_margin import PLANNED_SHARE


def balanced_gait_settings(config: RobotConfig, *, cycle_s: float | None = None, rate_hz: float | None = None,
                           max_step_m: float | None = None, clearance_m: float | None = None,
                           clearance_asked: bool = False) -> BalancedGaitSettings:
    """``[gait]`` with the command line's overrides (``clearance_asked``: ``clearance_m`` is the user's, kept)."""
    g = config.gait
    return BalancedGaitSettings(cycle_s=cycle_s or g.cycle_s, rate_hz=rate_hz or g.rate_hz,
                                max_step_m=max_step_m or g.max_step_m,
                                clearance_m=g.clearance_m if clearance_m is None else clearance_m,
                                clearance_asked=clearance_asked)


def _leg_joint(config: RobotConfig, name: str):
    for joint in config.joints:
        if joint.name == name:
            return joint
    return None


def full_torque_error_deg(config: RobotConfig, name: str) -> float:
    """The stiffness a leg servo walks with (deg of error at full torque): what the gain register holds
    after the ``[servo]`` setting is written (a register holds whole steps: an AX-12A asked for 2 deg gets
    compliance slope 4, 1.17 deg), else its factory gain's. The sag feedforward divides by this."""
    joint = _leg_joint(config, name)
    if config.servo.full_torque_error_deg is not None:
        return gain_for_error(joint.model, config.servo.full_torque_error_deg).full_torque_error_deg
    return joint.model.full_torque_error_deg


def servo_stiffness_nm_per_rad(config: RobotConfig) -> np.ndarray:
    """Each leg joint's position-loop stiffness kp = stall torque / full-torque error (N m/rad, LEG_JOINTS
    order; the servo models' datasheet stall torques, gaitbot.servos.models, or the ``[servo]`` override)."""
    out = []
    for name in LEG_JOINTS:
        joint = _leg_joint(config, name)
        stall = config.servo.stall_torque_nm or joint.model.stall_torque_nm
        out.append(stall / math.radians(full_torque_error_deg(config, name)))
    return np.array(out)


def leg_limits_rad(config: RobotConfig) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) of the 12 leg joints in LEG_JOINTS order (a held joint: its hold angle)."""
    lower, upper = [], []
    for name in LEG_JOINTS:
        j = _leg_joint(config, name)
        lo, hi = (j.hold_deg, j.hold_deg) if j.hold_deg is not None else (j.min_deg, j.max_deg)
        lower.append(math.radians(lo))
        upper.append(math.radians(hi))
    return np.array(lower), np.array(upper)


def velocity_limit_dps(config: RobotConfig) -> float:
    return min(j.max_velocity_dps for j in config.walking_joints)


def motion_measure(config: RobotConfig):
    """``measure(q_rad, rate_hz) -> (share, peak deg/s)`` of (N, 12) leg angles (LEG_JOINTS order) for the
    speed fit: the largest share of any joint's velocity or acceleration limit, and the fastest joint's
    speed, as its servo is sent them (gaitbot.robot.joint_motion, the definition ``gaitbot check`` uses)."""
    def measure(q_rad, rate_hz: float):
        t = np.arange(len(q_rad)) / rate_hz
        angles = np.degrees(full_angles_rad(config, q_rad, LEG_JOINTS))
        v, a = limit_shares(config, t, angles)
        velocity, _ = joint_motion(t, as_sent_deg(config, angles))
        peak_dps = float(np.abs(velocity).max()) if len(velocity) else 0.0
        return float(max(v.max(), a.max())), peak_dps
    return measure


def check_balanced_robot(config: RobotConfig) -> None:
    """The balanced walker moves all twelve leg joints; a robot must have them (held ones at 0)."""
    for name in LEG_JOINTS:
        j = _leg_joint(config, name)
        if j is None:
            raise BalancedWalkError(f"{config.path}: the balanced walk needs joint {name} (robots with hip and "
                                    f"ankle roll have all of {', '.join(LEG_JOINTS)})")
        if j.hold_deg is not None and abs(j.hold_deg) > 1e-9:
            raise BalancedWalkError(f"{config.path}: joints.{name} is held at {j.hold_deg:g} deg; the balanced "
                                    f"walk keeps it at 0 deg")


def balanced_walker(config: RobotConfig, gait: BalancedGaitSettings | None = None, balance=None) -> BalancedWalker:
    """An online balanced walker for the robot (steps appended while walking). Without ``balance``, the
    robot's ``[balance]`` fitted to its servos' limits with the planning margin for a steady walk at the
    gait's longest step (``fitted_settings``), as a planned walk is."""
    check_balanced_robot(config)
    gait = gait or balanced_gait_settings(config)
    if balance is None:
        fit = fitted_settings(config, gait)
        gait, balance = fit.gait, fit.balance
    return BalancedWalker(config.body, gait, balance,
                          limits_rad=leg_limits_rad(config), kp_nm_per_rad=servo_stiffness_nm_per_rad(config))


def fitted_settings(config: RobotConfig, gait: BalancedGaitSettings) -> SpeedFit:
    """The speed fit (its ``balance`` and ``gait``: the clearance may be lowered) of a steady walk at
    ``gait.max_step_m`` to the servos' limits (gaitbot.gait.balance.speed_fit, with PLANNED_SHARE)."""
    options = dict(limits_rad=leg_limits_rad(config), kp_nm_per_rad=servo_stiffness_nm_per_rad(config))
    return fit_to_servo_speed(config.body, gait, config.balance, velocity_limit_dps(config),
                              measure=motion_measure(config), share=PLANNED_SHARE, **options)


@dataclass(frozen=True)
class BalancedPlan:
    """A planned balanced walk: the walk's arrays, the speed fit that chose its settings, and the
    walker (heel strikes, planned steps) as the app and the simulation read them."""

    walk: BalancedWalk
    fit: SpeedFit
    walker: BalancedWalker

    @property
    def heel_strikes(self):
        return self.walk.heel_strikes

    @property
    def planned_steps(self):
        return self.walk.planned_steps


def plan_balanced(config: RobotConfig, step_lengths, gait: BalancedGaitSettings | None = None,
                  speed_fit: bool = True) -> BalancedPlan:
    """The whole walk, offline; with ``speed_fit`` the robot's ``[balance]`` is relaxed first where the
    cycle or step would ask a joint for more than PLANNED_SHARE of its max_velocity_dps or max_acceleration_dps2
    (gaitbot.gait.balance.speed_fit, gaitbot.robot.motion_margin)."""
    check_balanced_robot(config)
    gait = gait or balanced_gait_settings(config)
    options = dict(limits_rad=leg_limits_rad(config), kp_nm_per_rad=servo_stiffness_nm_per_rad(config))
    if speed_fit:
        # A walk of steady steps is fitted from the settings of the steady walk at the gait's longest step
        # on, so that steady walks of any length under one longest step walk with the same settings (a
        # family: eigen-gaits are fitted to them); other walks (varied steps) for their own steps.
        fit_options = dict(measure=motion_measure(config), share=PLANNED_SHARE, **options)
        limit = velocity_limit_dps(config)
        first = 0
        if len(set(step_lengths)) == 1:  # a steady walk: one family with the steady walk of its longest step
            first = fit_to_servo_speed(config.body, gait, config.balance, limit, **fit_options).relaxed
        fit = fit_to_servo_speed(config.body, gait, config.balance, limit, step_lengths, first=first, **fit_options)
        return BalancedPlan(fit.walk, fit, fit.walker)
    walker = plan_balanced_walk(config.body, step_lengths, gait, config.balance, **options)
    walk = walk_of(walker)
    return BalancedPlan(walk, SpeedFit(config.balance, gait, float("nan"), velocity_limit_dps(config), 0, walk, walker),
                        walker)


def with_balance(config: RobotConfig, **changes) -> RobotConfig:
    """The config with some ``[balance]`` settings changed (tools and tests)."""
    return replace(config, balance=replace(config.balance, **changes))
