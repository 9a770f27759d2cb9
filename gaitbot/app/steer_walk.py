"""The gait source of a steered walk (``--velocity``/``--duration``, ``--commands``: gaitbot.app.steer_options):
the command schedule, the planned walk, and the plan's summary for ``gaitbot plan`` (docs/steering.md).
``steered_plan`` is the steered gait source of gaitbot.app.planned_walk.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gaitbot.app.options import MAX_STEPS, UsageError, file_option
from gaitbot.app.steer_options import steer_sources
from gaitbot.gait.steer.command import CommandError, parse_velocity, read_commands
from gaitbot.gait.steer.planner import Footstep
from gaitbot.gait.steer.schedule import CommandSchedule
from gaitbot.robot.balanced_walk import BalancedPlan, balanced_gait_settings
from gaitbot.robot.steered_walk import plan_steered

MAX_DURATION_S = 3600.0
COMMAND_INTEGRATION_S = 0.01


def schedule_of(args) -> CommandSchedule:
    """The command schedule the options ask for; bad combinations are refused with the flags named."""
    duration, distance = getattr(args, "duration", None), getattr(args, "distance", None)
    if getattr(args, "commands", None) is not None:
        for flag in ("velocity", "duration", "distance", "steps"):
            if getattr(args, flag, None) is not None:
                raise UsageError(f"--commands: the file holds the walk's commands; leave --{flag} out")
        return CommandSchedule.of(read_commands(file_option(args.commands, "--commands")), args.commands)
    if getattr(args, "steps", None) is not None:
        raise UsageError("--velocity: give --duration S (or --distance M), not --steps")
    command = parse_velocity(args.velocity)
    if duration is not None and distance is not None:
        raise UsageError("--velocity: give --duration S or --distance M, not both")
    if distance is not None:
        if command.vy_m_s != 0.0 or command.wz_deg_s != 0.0 or command.vx_m_s == 0.0:
            raise UsageError("--velocity with --distance walks straight: VX nonzero, VY and WZ 0 "
                             f"(got {args.velocity}); give --duration S for any other walk")
        if not (math.isfinite(distance) and distance > 0):
            raise UsageError(f"--distance must be a positive number of metres, got {distance!r}")
        duration = distance / abs(command.vx_m_s)
    if duration is None:
        raise UsageError("--velocity: give --duration S (how long it holds) or --distance M (a straight walk)")
    if not (math.isfinite(duration) and 0 < duration <= MAX_DURATION_S):
        raise UsageError(f"--duration must be more than 0 and at most {MAX_DURATION_S:g} seconds, got {duration!r}")
    return CommandSchedule.steady(command, duration)


@dataclass(frozen=True, eq=False)
class SteeredPlan(BalancedPlan):
    """A steered balanced walk: the plan, its footsteps and the schedule they were planned from."""

    footsteps: tuple[Footstep, ...] = ()
    schedule: CommandSchedule | None = None


def steered_plan(source, args) -> "SteeredPlan":
    """The steered walk of the options (``--velocity``, ``--commands``) for the loaded robot (``source``)."""
    if not source.balanced:
        name = source.robot.name if source.robot is not None else "this leg"
        raise UsageError(f"--{steer_sources(args)[0]}: {name} walks with the planar walker, which walks straight; "
                         "steering needs a robot whose legs roll and turn (hip yaw and roll joints)")
    try:
        schedule = schedule_of(args)
        gait = balanced_gait_settings(source.robot, cycle_s=source.settings.cycle_s, rate_hz=source.settings.rate_hz,
                                      max_step_m=getattr(args, "max_step", None) or source.default_step_m,
                                      clearance_m=source.settings.clearance, clearance_asked=source.clearance_asked)
        plan, steps = plan_steered(source.robot, schedule, gait, MAX_STEPS)
    except CommandError as exc:
        raise UsageError(str(exc)) from None
    return SteeredPlan(plan.walk, plan.fit, plan.walker, tuple(steps), schedule)


def commanded_pose(schedule: CommandSchedule) -> tuple[float, float, float]:
    """Where the commands alone would take the robot: (x m, y m, heading deg), integrating each command
    in the robot's turning frame from the command clock's 0 to the stop."""
    x = y = heading = 0.0
    n = int(math.ceil(schedule.end_s / COMMAND_INTEGRATION_S))
    for k in range(n):
        t = k * COMMAND_INTEGRATION_S
        dt = min(COMMAND_INTEGRATION_S, schedule.end_s - t)
        c = schedule.at(t)
        mid = heading + 0.5 * math.radians(c.wz_deg_s) * dt
        x += (math.cos(mid) * c.vx_m_s - math.sin(mid) * c.vy_m_s) * dt
        y += (math.sin(mid) * c.vx_m_s + math.cos(mid) * c.vy_m_s) * dt
        heading += math.radians(c.wz_deg_s) * dt
    return x, y, math.degrees(heading)


def planned_pose(plan: SteeredPlan) -> tuple[float, float, float]:
    """Where the plan ends, from where it starts: (x m, y m, heading deg) of the midpoint between the
    ankles and the feet's mean yaw (unwrapped: a full turn is 360)."""
    ankles = plan.walk.ankles_m
    start, end = ankles[0, :, :2].mean(0), ankles[-1, :, :2].mean(0)
    return float(end[0] - start[0]), float(end[1] - start[1]), float(np.degrees(plan.walk.torso_yaw_rad[-1]))


def steered_plan_summary(source, plan: SteeredPlan) -> dict:
    """A steered plan as a JSON-ready object: each footstep, and the commanded and planned end poses."""
    walk = plan.walk
    strikes = [h for h in walk.heel_strikes]
    steps = []
    for k, (f, p) in enumerate(zip(plan.footsteps, walk.planned_steps), start=1):
        steps.append({"index": k, "leg": f.foothold.side, "dx_m": f.dx_m, "dy_m": f.dy_m, "dtheta_deg": f.dtheta_deg,
                      "foothold_m": [f.foothold.x_m, f.foothold.y_m], "yaw_deg": math.degrees(f.foothold.yaw_rad),
                      "start_s": p.start_s, "end_s": strikes[k - 1].t_s, "clipped": f.clipped})
    cx, cy, ch = commanded_pose(plan.schedule)
    px, py, ph = planned_pose(plan)
    return {"robot": source.robot.name, "walker": "balanced, steered", "n_steps": len(steps),
            "duration_s": float(walk.t_s[-1]), "rate_hz": plan.walker.rate_hz, "steps": steps,
            "commanded": {"x_m": cx, "y_m": cy, "heading_deg": ch},
            "planned": {"x_m": px, "y_m": py, "heading_deg": ph},
            "clipped": any(f.clipped for f in plan.footsteps),
            "crouch_knee_deg": plan.fit.balance.crouch_knee_deg,
            "double_support_share": plan.fit.balance.double_support_share,
            "progression_end": plan.fit.balance.progression_end, "clearance_m": plan.fit.gait.clearance_m,
            "peak_joint_speed_dps": plan.fit.peak_dps}


def print_steered_plan(summary: dict) -> None:
    print(f"{'step':>4} {'leg':>5} {'dx m':>8} {'dy m':>8} {'dth deg':>8} {'start s':>8} {'end s':>7} "
          f"{'x m':>8} {'y m':>8} {'yaw deg':>8}")
    for s in summary["steps"]:
        print(f"{s['index']:>4} {s['leg']:>5} {s['dx_m']:8.4f} {s['dy_m']:8.4f} {s['dtheta_deg']:8.2f} "
              f"{s['start_s']:8.3f} {s['end_s']:7.3f} {s['foothold_m'][0]:8.4f} {s['foothold_m'][1]:8.4f} "
              f"{s['yaw_deg']:8.2f}")
    c, p = summary["commanded"], summary["planned"]
    print(f"{summary['robot']}: {summary['n_steps']} steps in {summary['duration_s']:.2f} s; commanded "
          f"({c['x_m']:.3f} m, {c['y_m']:.3f} m, {c['heading_deg']:.1f} deg), planned ({p['x_m']:.3f} m, "
          f"{p['y_m']:.3f} m, {p['heading_deg']:.1f} deg) (x, y, heading from the start; dx, dy, dth: each "
          f"foothold from the stance foot, in its frame)" + ("; the robot's [steer] limits clipped the commands"
                                                            if summary["clipped"] else ""))
