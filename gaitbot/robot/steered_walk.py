"""From a robot config and timed commands to a steered balanced walk (docs/steering.md).

The robot's ``[steer]`` limits bound the footstep planner (gaitbot.gait.steer.planner), its ``[gait]``
and ``[balance]`` time the steps, and the walk is planned and fitted to the servos' speed exactly as a
straight one (gaitbot.robot.balanced_walk.plan_balanced, whose steps are then footholds): a straight
command gives the very steps, and so the very walk, of ``--steps`` with the same lengths.
"""

from __future__ import annotations

from gaitbot.gait.balance.step_plan import StepPlanner
from gaitbot.gait.balance.walker import BalancedGaitSettings, BalancedWalkError
from gaitbot.gait.balance.zmp_reference import Timing
from gaitbot.gait.steer.planner import Footstep, FootstepPlanner
from gaitbot.gait.steer.schedule import CommandSchedule, plan_footsteps
from gaitbot.robot.balanced_walk import BalancedPlan, balanced_gait_settings, plan_balanced
from gaitbot.robot.config import RobotConfig


class SteeringError(BalancedWalkError):
    """A robot that cannot steer (no [steer] table, no hip yaw joints): one line."""


def steering_timing(config: RobotConfig, gait: BalancedGaitSettings) -> Timing:
    return Timing.of(gait.cycle_s, gait.rate_hz, config.balance.double_support_share)


def footstep_planner(config: RobotConfig, gait: BalancedGaitSettings | None = None) -> FootstepPlanner:
    """A planner for the robot standing where every balanced walk starts (gaitbot.gait.balance.step_plan)."""
    if config.steer is None:
        raise SteeringError(f"{config.path}: robot {config.name} has no [steer] table (steering limits; "
                            f"docs/robot-config.md): it walks straight only (--steps, --distance)")
    gait = gait or balanced_gait_settings(config)
    timing = steering_timing(config, gait)
    feet = StepPlanner.start_feet_of(config.body.geometry)
    return FootstepPlanner(config.body.geometry, config.steer, timing.step_frames / timing.rate_hz, feet)


def steered_footsteps(config: RobotConfig, schedule: CommandSchedule, gait: BalancedGaitSettings | None = None,
                      max_steps: int = 1000) -> list[Footstep]:
    """Every footstep of the walk the schedule commands (the command clock starts at the first step)."""
    gait = gait or balanced_gait_settings(config)
    planner = footstep_planner(config, gait)
    t = steering_timing(config, gait)
    return plan_footsteps(planner, schedule, (t.step_frames + t.ss_frames) / t.rate_hz, t.step_frames / t.rate_hz,
                          max_steps)


def plan_steered(config: RobotConfig, schedule: CommandSchedule, gait: BalancedGaitSettings | None = None,
                 max_steps: int = 1000) -> tuple[BalancedPlan, list[Footstep]]:
    """The steered walk, offline (speed-fitted as plan_balanced), and the footsteps it walks."""
    steps = steered_footsteps(config, schedule, gait, max_steps)
    return plan_balanced(config, steps, gait), steps
