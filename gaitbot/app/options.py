"""Reading the command line's options: the one place each option is validated and turned into rooms' inputs.

Robot loading, ``--rate`` / ``--reply-timeout-ms`` / length checks written
once, the leg and walk settings (``gait_source``) and the step list. Errors for people are raised as
``UsageError`` (one line, exit status 2, nothing sent to a servo).
"""

from __future__ import annotations

import math

from gaitbot.errors import UserError
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.planning import perturb_steps, steps_for_distance
from gaitbot.gait.walker import WalkSettings, longest_step_m
from gaitbot.robot.calibration_file import load_robot_with_calibration
from gaitbot.robot.config import RATE_RANGE_HZ, ConfigError, RobotConfig, check_bus_rate
from gaitbot.robot.walk_settings import GaitSource, leg_geometry, walk_settings


class UsageError(UserError, ValueError):
    """Bad input from the user: printed as one line, exit status 2, nothing sent to a servo."""


def load_robot(robot: str | None, calibration: str | None = None) -> RobotConfig:
    """The robot config named by ``--robot`` (a path or a shipped name), or the built-in default, with its
    calibration applied (``--calibration FILE``, else ``<config>.calibration.toml`` beside it if there is
    one: gaitbot.robot.calibration_file); a ``gait.rate_hz`` the bus cannot carry is refused at load
    (gaitbot.robot.config.check_bus_rate)."""
    if robot is not None and not robot.strip():
        raise UsageError("--robot: empty name; give a .toml path or a shipped robot name (leave --robot out for "
                         "the default robot)")
    if calibration is not None and not calibration.strip():
        raise UsageError("--calibration: empty file name")
    try:
        return load_robot_with_calibration(robot, calibration)
    except (ConfigError, UserError):
        raise
    except (OSError, ValueError, KeyError) as exc:
        raise UsageError(f"--robot {robot}: {exc}") from None


def file_option(value: str, flag: str) -> str:
    """A file named on the command line: an empty name is refused (it would be read as the current folder)."""
    if value is None or not str(value).strip():
        raise UsageError(f"{flag}: empty file name")
    return value


def positive_option(value: float | None, flag: str, what: str) -> None:
    """Refuse an option that is given but not a finite positive number: ``flag must be what, got value``."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise UsageError(f"{flag} must be {what}, got {value!r}")


def check_reply_timeout(reply_timeout_ms: float | None) -> None:
    """``--reply-timeout-ms``: how long to wait for each status packet, if given."""
    positive_option(reply_timeout_ms, "--reply-timeout-ms", "a positive number of milliseconds")
    if reply_timeout_ms is not None and reply_timeout_ms > MAX_REPLY_TIMEOUT_MS:
        raise UsageError(f"--reply-timeout-ms must be at most {MAX_REPLY_TIMEOUT_MS:g} ms, got {reply_timeout_ms:g}")


def check_rate_option(config: RobotConfig, rate_hz: float | None, label: str | None = None) -> None:
    """``--rate`` (or a trajectory file's own rate, named by ``label``): a positive frame rate that the
    robot's bus carries with its read-back."""
    if rate_hz is None:
        return
    check_rate_range(rate_hz, label or "--rate")
    try:
        check_bus_rate(config, rate_hz)
    except ValueError as exc:
        raise UsageError(f"{label or f'--rate {rate_hz:g}'}: {exc}") from None


def check_rate_range(rate_hz: float, label: str = "--rate") -> None:
    """A frame rate within RATE_RANGE_HZ (10..200 Hz): slower, each goal is a jump a position servo makes at full
    speed; faster, no read-back fits in a frame."""
    low, high, _ = RATE_RANGE_HZ
    if not (math.isfinite(rate_hz) and low <= rate_hz <= high):
        raise UsageError(f"{label} must be a frame rate within {low:g}..{high:g} Hz, got {rate_hz:g}")


def gait_source(args, robot: RobotConfig | None = None) -> GaitSource:
    """Geometry and settings from ``robot`` (else ``--robot``, or the default robot, loaded here), with the
    ``--thigh/--shank/--foot``, ``--rate``, ``--cycle`` and ``--clearance`` overrides."""
    if robot is None:
        robot = load_robot(getattr(args, "robot", None), getattr(args, "calibration", None))
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
    if rate is not None:
        check_rate_range(rate)
    settings = walk_settings(robot, rate)
    cycle = getattr(args, "cycle", None)
    if cycle is not None and not (math.isfinite(cycle) and CYCLE_RANGE_S[0] <= cycle <= CYCLE_RANGE_S[1]):
        raise UsageError(f"--cycle must be {CYCLE_RANGE_S[0]:g}..{CYCLE_RANGE_S[1]:g} seconds (two steps), got {cycle!r}")
    if cycle is not None:
        settings = WalkSettings(cycle, settings.rate_hz, settings.clearance)
    clearance = getattr(args, "clearance", None)
    if clearance is not None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise UsageError(f"--clearance must be 0 or more metres, got {clearance!r}")
        settings = WalkSettings(settings.cycle_s, settings.rate_hz, clearance)
    reachable = longest_step_m(geometry, settings)
    max_step = robot.gait.max_step_m if robot_for_limits is not None else reachable
    asked = clearance is not None
    if robot_for_limits is not None and robot.is_3d:  # its max_step_m is the default; the leg's reach the limit
        return GaitSource(geometry, settings, reachable, robot, default_step_m=min(max_step, reachable),
                          clearance_asked=asked)
    return GaitSource(geometry, settings, min(max_step, reachable), robot_for_limits, clearance_asked=asked)


#: The most steps one walk may have (planning costs about 5 ms a step), and the longest --distance.
MAX_STEPS = 1000
MAX_DISTANCE_M = 100.0
#: --cycle (s): a walk cycle (two steps) shorter than a servo can follow or longer than any walk needs.
CYCLE_RANGE_S = (0.2, 10.0)
#: --seed must fit numpy's seeding (an unsigned 32-bit integer here).
MAX_SEED = 2**32 - 1
#: The longest wait for one status packet --reply-timeout-ms may set (start-up exchanges; a frame's
#: read-back is bounded by its frame anyway).
MAX_REPLY_TIMEOUT_MS = 1000.0


def walked_by(source: GaitSource) -> str:
    """Whose leg a plan or a trajectory is for, said in every command's output (a default is never silent)."""
    g = source.geometry
    if source.robot is not None:
        return source.robot.name
    return f"a leg of {1000 * g.thigh:.0f} / {1000 * g.shank:.0f} / {1000 * g.foot:.0f} mm (thigh / shank / foot)"


def parse_step_list(text: str) -> list[float]:
    """``0.3,0.4,...`` -> floats; one clear error for anything else."""
    if text is None or not text.strip():
        raise UsageError("--steps: empty list; give step lengths in metres, e.g. --steps 0.05,0.06,0.05")
    items = text.split(",")
    if len(items) > MAX_STEPS:
        raise UsageError(f"--steps: {len(items)} steps, more than the {MAX_STEPS} one walk may have")
    values = []
    for i, item in enumerate(items, start=1):
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
        if distance > MAX_DISTANCE_M:
            raise UsageError(f"--distance {distance:g} m is longer than one walk may be (at most {MAX_DISTANCE_M:g} m)")
        default = source.default_step_m if source.default_step_m is not None else source.max_step_m
        max_step = default if args.max_step is None else args.max_step
        if not math.isfinite(max_step) or max_step <= 0:
            raise UsageError(f"--max-step must be a positive number of metres, got {max_step!r}")
        if max_step > source.max_step_m * (1 + 1e-12):
            raise UsageError(f"--max-step {max_step:g} m is longer than this robot's longest step "
                             f"{source.max_step_m:.4g} m")
        if distance / max_step > MAX_STEPS:
            flag = "--max-step" if args.max_step is not None else "--distance"
            raise UsageError(f"{flag}: --distance {distance:g} m in steps of at most {max_step:g} m needs "
                             f"{math.ceil(distance / max_step)} steps, more than the {MAX_STEPS} one walk may have")
        steps = steps_for_distance(distance, max_step)
    for i, value in enumerate(steps, start=1):
        if value < 0:
            raise UsageError(f"--steps: step {i} is {value:g} m; step lengths must be 0 or more (a robot whose legs "
                             f"roll walks backwards when steered: --velocity -0.02,0,0 --duration S)")
        if value > source.max_step_m * (1 + 1e-12):
            what = ("max_step_m in the robot config" if source.robot is not None and not source.balanced
                    else "the leg's reachable maximum")
            raise UsageError(f"--steps: step {i} is {value:g} m, longer than {source.max_step_m:.4g} m ({what})")
    sigma = getattr(args, "perturb", None)
    if sigma is not None and not (math.isfinite(sigma) and 0 <= sigma <= source.max_step_m):
        raise UsageError(f"--perturb must be 0..{source.max_step_m:.4g} m (the longest step), got {sigma!r}")
    seed = getattr(args, "seed", None)
    if seed is not None and not 0 <= seed <= MAX_SEED:
        raise UsageError(f"--seed must be 0..{MAX_SEED}, got {seed}")
    if sigma:
        steps = perturb_steps(steps, sigma, getattr(args, "seed", None), source.max_step_m)
    return steps
