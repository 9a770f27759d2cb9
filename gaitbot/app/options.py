"""Wiring for the commands: from arguments to a robot, a step plan, a trajectory and a bus.

No numerics here: each function joins rooms (gait -> robot -> bus -> stream) the one way data
flows. Errors for people are raised as ``UsageError`` (one line, exit status 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gaitbot.bus.base import RegisterWrite
from gaitbot.bus.budget import check_rate
from gaitbot.check import CheckReport, check_trajectory, trajectory_angles_deg
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.segments import GaitGenerationError
from gaitbot.gait.planning import perturb_steps, steps_for_distance
from gaitbot.gait.step_length import StepLengthError
from gaitbot.gait.trajectory import Trajectory
from gaitbot.gait.walker import OnlineWalker, WalkSettings, make_context, plan_walk, trajectory_of
from gaitbot.robot.config import ConfigError, RobotConfig, default_config_path, load_robot_config, resolve_config
from gaitbot.robot.gait_setup import leg_geometry, walk_settings
from gaitbot.robot.servo_gains import gain_plan


class UsageError(ValueError):
    """Bad input from the user: printed as one line, exit status 2, nothing sent to a servo."""


def bus_budget_check(config: RobotConfig) -> None:
    """Refuse a frame rate the bus cannot carry (writes plus a read-back) with margin."""
    try:
        check_rate(config.gait.rate_hz, config.bus.backend, config.bus.protocol, config.joints[0].model,
                   len(config.joints), config.bus.baudrate, read_back=True)
    except ValueError as exc:
        raise ConfigError(config.path, "gait.rate_hz", str(exc)) from None


def load_robot(robot: str | None) -> RobotConfig:
    """The robot config named by ``--robot`` (a path or a shipped name), or the built-in default."""
    try:
        path = resolve_config(robot) if robot else default_config_path()
        return load_robot_config(path, extra_checks=[bus_budget_check])
    except ConfigError:
        raise
    except (OSError, ValueError, KeyError) as exc:
        raise UsageError(f"--robot {robot}: {exc}") from None


def gain_writes(config: RobotConfig) -> tuple[RegisterWrite, ...]:
    """What a session writes before torque on to give every servo ``[servo] full_torque_error_deg``
    (nothing without it), one register write per servo model and register (checked at load)."""
    return tuple(RegisterWrite(ids, w.address, w.length, w.value, w.name)
                 for setting, ids in gain_plan(config) for w in setting.writes)


def gain_notes(config: RobotConfig) -> list[str]:
    """One line per servo model for people: which gain is written and the stiffness it gives."""
    return [f"servo stiffness: {setting.describe()}, written to ids {', '.join(map(str, sorted(ids)))} before "
            f"torque on (in RAM: lasts until power-off)" for setting, ids in gain_plan(config)]


@dataclass(frozen=True)
class GaitSource:
    """Where a walk's geometry and settings come from, and the longest step allowed (metres)."""

    geometry: LegGeometry
    settings: WalkSettings
    max_step_m: float
    robot: RobotConfig | None


def gait_source(args) -> GaitSource:
    """Geometry and settings from ``--robot`` (or the default robot), with ``--thigh/--shank/--foot`` overrides."""
    robot = load_robot(getattr(args, "robot", None))
    geometry = leg_geometry(robot)
    overrides = {k: getattr(args, k, None) for k in ("thigh", "shank", "foot")}
    if any(v is not None for v in overrides.values()):
        for name, value in overrides.items():
            if value is not None and not (math.isfinite(value) and value > 0):
                raise UsageError(f"--{name} must be a positive length in metres, got {value!r}")
        geometry = LegGeometry(thigh=overrides["thigh"] or geometry.thigh, shank=overrides["shank"] or geometry.shank,
                               foot=overrides["foot"] or geometry.foot, hip_width=geometry.hip_width,
                               ankle_height=0.0 if overrides["foot"] else geometry.ankle_height,
                               heel_back=0.0 if overrides["foot"] else geometry.heel_back)
        robot_for_limits = None  # a custom leg is not the robot whose joint limits are configured
    else:
        robot_for_limits = robot
    rate = getattr(args, "rate", None)
    if rate is not None and not (math.isfinite(rate) and rate > 0):
        raise UsageError(f"--rate must be a positive frame rate in Hz, got {rate!r}")
    settings = walk_settings(robot, rate)
    clearance = getattr(args, "clearance", None)
    if clearance is not None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise UsageError(f"--clearance must be 0 or more metres, got {clearance!r}")
        settings = WalkSettings(settings.cycle_s, settings.rate_hz, clearance)
    reachable = make_context(geometry, settings).inverse.max_step_length
    max_step = robot.gait.max_step_m if robot_for_limits is not None else reachable
    return GaitSource(geometry, settings, min(max_step, reachable), robot_for_limits)


def parse_step_list(text: str) -> list[float]:
    """``0.3,0.4,...`` -> floats; one clear error for anything else."""
    if text is None or not text.strip():
        raise UsageError("--steps: empty list; give step lengths in metres, e.g. --steps 0.05,0.06,0.05")
    values = []
    for i, item in enumerate(text.split(","), start=1):
        try:
            value = float(item)
        except ValueError:
            raise UsageError(f"--steps: item {i} {item.strip()!r} is not a number") from None
        if not math.isfinite(value):
            raise UsageError(f"--steps: item {i} {item.strip()!r} is not a finite number")
        values.append(value)
    return values


def step_lengths(args, source: GaitSource) -> list[float]:
    """The requested steps (metres) from ``--steps`` or ``--distance``/``--max-step``, perturbed if asked."""
    if getattr(args, "steps", None) is not None:
        steps = parse_step_list(args.steps)
    else:
        distance = args.distance
        if distance is None or not math.isfinite(distance) or distance <= 0:
            raise UsageError(f"--distance must be a positive number of metres, got {distance!r}")
        max_step = source.max_step_m if args.max_step is None else args.max_step
        if not math.isfinite(max_step) or max_step <= 0:
            raise UsageError(f"--max-step must be a positive number of metres, got {max_step!r}")
        if max_step > source.max_step_m * (1 + 1e-12):
            raise UsageError(f"--max-step {max_step:g} m is longer than this robot's longest step "
                             f"{source.max_step_m:.4g} m")
        steps = steps_for_distance(distance, max_step)
    for i, value in enumerate(steps, start=1):
        if value < 0:
            raise UsageError(f"--steps: step {i} is {value:g} m; step lengths must be 0 or more")
        if value > source.max_step_m * (1 + 1e-12):
            what = "max_step_m in the robot config" if source.robot is not None else "the leg's reachable maximum"
            raise UsageError(f"--steps: step {i} is {value:g} m, longer than {source.max_step_m:.4g} m ({what})")
    sigma = getattr(args, "perturb", None)
    if sigma:
        steps = perturb_steps(steps, sigma, getattr(args, "seed", None), source.max_step_m)
    return steps


def build_walk(args) -> tuple[GaitSource, OnlineWalker]:
    """A planned, closed walker for the arguments (all frames computed)."""
    source = gait_source(args)
    steps = step_lengths(args, source)
    try:
        return source, plan_walk(source.geometry, steps, source.settings)
    except StepLengthError as exc:
        raise UsageError(str(exc)) from None


def plan_summary(source: GaitSource, walker: OnlineWalker) -> dict:
    """The plan as a JSON-ready object: requested steps, the closing step, footholds and totals."""
    steps = [s.to_dict() for s in walker.planned_steps if not s.closing]
    closing = [s.to_dict() for s in walker.planned_steps if s.closing]
    n_frames = walker._planned_frames
    return {
        "robot": source.robot.name if source.robot is not None else None,
        "leg_length_m": source.geometry.leg_length,
        "cycle_s": walker.ctx.cycle_s,
        "rate_hz": walker.ctx.rate_hz,
        "reachable_step_m": list(walker.ctx.inverse.reachable_range),
        "max_step_m": source.max_step_m,
        "steps": steps,
        "closing_step": closing[0] if closing else None,
        "heel_strikes": [{"t_s": h.t_s, "leg": h.leg, "x_m": h.x_m} for h in walker.heel_strikes],
        "total_distance_m": walker.heel_strikes[-1].x_m if walker.heel_strikes else 0.0,
        "n_steps": len(steps),
        "duration_s": (n_frames - 1) / walker.ctx.rate_hz,
        "n_frames": n_frames,
    }


def preflight(config: RobotConfig, trajectory: Trajectory, margin_deg: float = 0.0) -> CheckReport:
    """The limit check ``gaitbot walk`` runs before anything moves (the same code as ``gaitbot check``)."""
    return check_trajectory(config, trajectory.t_s, trajectory_angles_deg(config, trajectory.angles_rad), margin_deg)


def joint_limits_ticks(config: RobotConfig) -> tuple[float, float]:
    """The slowest joint's velocity and acceleration limits in ticks/s and ticks/s^2 (for ramps)."""
    vel = min(math.radians(j.max_velocity_dps) * j.model.ticks_per_rad for j in config.joints)
    acc = min(math.radians(j.max_acceleration_dps2) * j.model.ticks_per_rad for j in config.joints)
    return vel, acc


@dataclass(frozen=True)
class FileWalk:
    """A trajectory file walked as it is (``walk --trajectory``): its heel strikes stand for the plan."""

    heel_strikes: tuple

    @property
    def planned_steps(self) -> tuple:
        return self.heel_strikes


#: A trajectory file's sample times must be this close to one period apart (share of the period).
UNIFORM_RATE_TOL = 1e-3


def trajectory_file_walk(args) -> tuple[GaitSource, FileWalk, Trajectory]:
    """``--trajectory FILE``: the file streamed frame by frame at its own (uniform) rate, which the bus must carry."""
    if getattr(args, "rate", None) is not None:
        raise UsageError("--rate: a trajectory file is walked at its own frame rate; leave --rate out")
    source = gait_source(args)
    trajectory = Trajectory.load(args.trajectory)
    periods = np.diff(trajectory.t_s)
    period = float(np.median(periods))
    worst = float(np.abs(periods - period).max())
    if worst > UNIFORM_RATE_TOL * period:
        k = int(np.argmax(np.abs(periods - period)))
        raise UsageError(f"--trajectory {args.trajectory}: samples are not evenly spaced (row {k + 3} comes "
                         f"{periods[k]:.6g} s after the one before, the median spacing is {period:.6g} s); "
                         f"the robot is sent one row per frame")
    rate = 1.0 / period
    if source.robot is not None:
        config = source.robot
        try:
            check_rate(rate, config.bus.backend, config.bus.protocol, config.joints[0].model, len(config.joints),
                       config.bus.baudrate, read_back=True)
        except ValueError as exc:
            raise UsageError(f"--trajectory {args.trajectory}: its {rate:.4g} Hz: {exc}") from None
    settings = WalkSettings(source.settings.cycle_s, rate, source.settings.clearance)
    return GaitSource(source.geometry, settings, source.max_step_m, source.robot), \
        FileWalk(tuple(trajectory.heel_strikes)), trajectory


def trajectory_for_robot(args) -> tuple[GaitSource, OnlineWalker, Trajectory]:
    if getattr(args, "trajectory", None) is not None:
        return trajectory_file_walk(args)
    if getattr(args, "terrain", None) is not None:
        source, walk = build_terrain_walk(args)
        return source, walk, walk.trajectory
    source, walker = build_walk(args)
    return source, walker, trajectory_of(walker)


def terrain_envelope(source: GaitSource, course):
    """The robot's step envelope (its config's [terrain], else the unmeasured default), tightened by the
    course's own max_rise_m / max_step_m; a course asking for more than the robot can do is refused."""
    from gaitbot.gait.terrain.envelope import StepEnvelope

    g = source.geometry
    reach = source.robot.terrain if source.robot is not None else None
    who = source.robot.name if source.robot is not None else "this leg"
    if reach is not None:
        env = StepEnvelope.for_foot(g.foot, reach.max_rise_m, reach.max_drop_m, reach.max_gap_m, who)
    else:
        env = StepEnvelope.default(g.foot, g.leg_length, f"{who}, not measured")
    if course.max_rise_m is not None:
        if course.max_rise_m > max(env.max_rise, env.max_drop) + 1e-12:
            raise UsageError(f"{course.path}: course.max_rise_m: {course.max_rise_m:g} m is more than {who} can step "
                             f"(max rise {env.max_rise:.3f} m, drop {env.max_drop:.3f} m)")
        env = replace(env, max_rise=min(env.max_rise, course.max_rise_m), max_drop=min(env.max_drop, course.max_rise_m))
    if course.max_step_m is not None:
        if course.max_step_m > env.longest + 1e-12:
            raise UsageError(f"{course.path}: course.max_step_m: {course.max_step_m:g} m is longer than {who} can step "
                             f"between surfaces (max {env.longest:.3f} m)")
        env = replace(env, max_gap=max(0.0, course.max_step_m - env.reference_step))
    return env


def terrain_settings(source: GaitSource, course, clearance_override: float | None = None):
    """How to walk a course: the file's values, else the robot's (clearance, joint ranges and limits, step
    envelope)."""
    from gaitbot.gait.terrain.walk import TerrainSettings, default_weights

    lo = hi = speed = accel = None
    if source.robot is not None:
        pairs = list(zip(source.robot.joints[:3], source.robot.joints[3:6]))  # (left, right) hip, knee, ankle
        lo = tuple(math.radians(max(a.min_deg, b.min_deg)) for a, b in pairs)
        hi = tuple(math.radians(min(a.max_deg, b.max_deg)) for a, b in pairs)
        speed = tuple(math.radians(min(a.max_velocity_dps, b.max_velocity_dps)) for a, b in pairs)
        accel = tuple(math.radians(min(a.max_acceleration_dps2, b.max_acceleration_dps2)) for a, b in pairs)
    clearance = course.clearance_m if course.clearance_m is not None else source.settings.clearance
    if clearance_override is not None:
        clearance = clearance_override
    return TerrainSettings(envelope=terrain_envelope(source, course), margin=course.margin_m, clearance=clearance,
                           weights=course.weights or default_weights(lo, hi), joint_lo=lo, joint_hi=hi,
                           joint_speed=speed, joint_accel=accel)


def build_terrain_walk(args):
    """Footholds, pelvis search and trajectory for ``--terrain FILE`` (seed 003 joined to the flat walker)."""
    from gaitbot.gait.terrain.footholds import CourseError
    from gaitbot.gait.terrain.walk import plan_terrain_walk
    from gaitbot.terrain_file import load_course

    source = gait_source(args)
    course = load_course(args.terrain)
    settings = terrain_settings(source, course, getattr(args, "clearance", None))
    try:
        walk = plan_terrain_walk(make_context(source.geometry, source.settings), course.terrain, course.start_m,
                                 course.end_m, settings, source.max_step_m)
    except CourseError as exc:
        raise UsageError(f"{course.path}: {exc}") from None
    except GaitGenerationError as exc:
        raise GaitGenerationError(f"{course.path}: {exc}") from None
    return source, walk


def terrain_plan_summary(source: GaitSource, walk) -> dict:
    """A terrain plan as a JSON-ready object: steps with their method, footholds, and the grid searches."""
    searches = [{"mds_m": list(r.point), "cost": r.cost, "centre_cost": r.centre_cost if math.isfinite(r.centre_cost)
                 else None, "evaluated": r.evaluated, "pruned": r.pruned, "full_grid": r.full_grid}
                for r in walk.search_reports]
    traj = walk.trajectory
    return {
        "robot": source.robot.name if source.robot is not None else None,
        "leg_length_m": source.geometry.leg_length,
        "rate_hz": walk.ctx.rate_hz,
        "steps": [s.to_dict() for s in walk.steps],
        "n_steps": len(walk.steps),
        "n_terrain_steps": sum(1 for s in walk.steps if s.method == "terrain"),
        "searches": searches,
        "cells_evaluated": sum(r.evaluated for r in walk.search_reports),
        "cells_full_search": sum(r.full_grid for r in walk.search_reports),
        "duration_s": float(traj.t_s[-1]),
        "n_frames": len(traj),
        "total_distance_m": walk.steps[-1].foothold_m - (walk.steps[0].foothold_m - walk.steps[0].length_m),
    }
