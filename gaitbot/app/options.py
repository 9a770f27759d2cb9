"""Reading the command line's options: the one place each option is validated and turned into rooms' inputs.

Robot loading (with the bus budget hook), ``--rate`` / ``--reply-timeout-ms`` / length checks written
once, the leg and walk settings (``gait_source``) and the step list. Errors for people are raised as
``UsageError`` (one line, exit status 2, nothing sent to a servo).
"""

from __future__ import annotations

import math

from gaitbot.bus.budget import bus_budget_check, check_robot_rate
from gaitbot.errors import UserError
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.planning import perturb_steps, steps_for_distance
from gaitbot.gait.walker import WalkSettings, make_context
from gaitbot.robot.config import ConfigError, RobotConfig, default_config_path, load_robot_config, resolve_config
from gaitbot.robot.walk_settings import GaitSource, leg_geometry, walk_settings


class UsageError(UserError, ValueError):
    """Bad input from the user: printed as one line, exit status 2, nothing sent to a servo."""


def load_robot(robot: str | None) -> RobotConfig:
    """The robot config named by ``--robot`` (a path or a shipped name), or the built-in default; a
    ``gait.rate_hz`` the bus cannot carry is refused at load (gaitbot.bus.budget)."""
    try:
        path = resolve_config(robot) if robot else default_config_path()
        return load_robot_config(path, extra_checks=[bus_budget_check])
    except ConfigError:
        raise
    except (OSError, ValueError, KeyError) as exc:
        raise UsageError(f"--robot {robot}: {exc}") from None


def positive_option(value: float | None, flag: str, what: str) -> None:
    """Refuse an option that is given but not a finite positive number: ``flag must be what, got value``."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise UsageError(f"{flag} must be {what}, got {value!r}")


def check_reply_timeout(reply_timeout_ms: float | None) -> None:
    """``--reply-timeout-ms``: how long to wait for each status packet, if given."""
    positive_option(reply_timeout_ms, "--reply-timeout-ms", "a positive number of milliseconds")


def check_rate_option(config: RobotConfig, rate_hz: float | None, label: str | None = None) -> None:
    """``--rate`` (or a trajectory file's own rate, named by ``label``): a positive frame rate that the
    robot's bus carries with its read-back."""
    if rate_hz is None:
        return
    positive_option(rate_hz, "--rate", "a positive frame rate in Hz")
    try:
        check_robot_rate(config, rate_hz)
    except ValueError as exc:
        raise UsageError(f"{label or f'--rate {rate_hz:g}'}: {exc}") from None


def gait_source(args) -> GaitSource:
    """Geometry and settings from ``--robot`` (or the default robot), with ``--thigh/--shank/--foot`` overrides."""
    robot = load_robot(getattr(args, "robot", None))
    geometry = leg_geometry(robot)
    overrides = {k: getattr(args, k, None) for k in ("thigh", "shank", "foot")}
    if any(v is not None for v in overrides.values()):
        for name, value in overrides.items():
            positive_option(value, f"--{name}", "a positive length in metres")
        geometry = LegGeometry(thigh=overrides["thigh"] or geometry.thigh, shank=overrides["shank"] or geometry.shank,
                               foot=overrides["foot"] or geometry.foot, hip_width=geometry.hip_width,
                               ankle_height=0.0 if overrides["foot"] else geometry.ankle_height,
                               heel_back=0.0 if overrides["foot"] else geometry.heel_back)
        robot_for_limits = None  # a custom leg is not the robot whose joint limits are configured
    else:
        robot_for_limits = robot
    rate = getattr(args, "rate", None)
    positive_option(rate, "--rate", "a positive frame rate in Hz")
    settings = walk_settings(robot, rate)
    cycle = getattr(args, "cycle", None)
    positive_option(cycle, "--cycle", "a positive number of seconds (two steps)")
    if cycle is not None:
        settings = WalkSettings(cycle, settings.rate_hz, settings.clearance)
    clearance = getattr(args, "clearance", None)
    if clearance is not None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise UsageError(f"--clearance must be 0 or more metres, got {clearance!r}")
        settings = WalkSettings(settings.cycle_s, settings.rate_hz, clearance)
    reachable = make_context(geometry, settings).inverse.max_step_length
    max_step = robot.gait.max_step_m if robot_for_limits is not None else reachable
    if robot_for_limits is not None and robot.is_3d:  # its max_step_m is the default; the leg's reach the limit
        return GaitSource(geometry, settings, reachable, robot, default_step_m=min(max_step, reachable))
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
        default = source.default_step_m if source.default_step_m is not None else source.max_step_m
        max_step = default if args.max_step is None else args.max_step
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
            what = ("max_step_m in the robot config" if source.robot is not None and not source.balanced
                    else "the leg's reachable maximum")
            raise UsageError(f"--steps: step {i} is {value:g} m, longer than {source.max_step_m:.4g} m ({what})")
    sigma = getattr(args, "perturb", None)
    if sigma:
        steps = perturb_steps(steps, sigma, getattr(args, "seed", None), source.max_step_m)
    return steps
