"""From the walk options (``--steps`` / ``--distance``, ``--terrain FILE``, ``--trajectory FILE``) to a
plan and a trajectory, for ``plan``, ``generate`` and ``walk``."""

from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from gaitbot.app.options import UsageError, check_rate_option, file_option, gait_source, step_lengths
from gaitbot.app.progress import callback, progress
from gaitbot.app.steer_options import steer_requested
from gaitbot.app.steer_walk import steered_walk
from gaitbot.gait.footfall import detect_heel_strikes
from gaitbot.gait.segments import GaitGenerationError
from gaitbot.gait.step_length import StepLengthError
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.terrain.footholds import CourseError
from gaitbot.gait.terrain.walk import plan_terrain_walk
from gaitbot.gait.trajectory import Trajectory
from gaitbot.gait.walker import OnlineWalker, WalkSettings, make_context, plan_walk, trajectory_of
from gaitbot.robot.balanced_walk import BalancedPlan, balanced_gait_settings, plan_balanced
from gaitbot.robot.walk_settings import GaitSource, terrain_settings


def build_walk(args) -> tuple[GaitSource, OnlineWalker]:
    """A planned, closed walker for the arguments (all frames computed)."""
    source = gait_source(args)
    steps = step_lengths(args, source)
    try:
        return source, plan_walk(source.geometry, steps, source.settings)
    except StepLengthError as exc:
        raise UsageError(str(exc)) from None
    except GaitGenerationError as exc:
        raise UsageError(f"{leg_origin(args, source)}: {exc}") from None


def leg_origin(args, source: GaitSource) -> str:
    """Where the leg and gait settings of a walk come from, for a message about a walk they cannot make."""
    flags = [f"--{name}" for name in ("thigh", "shank", "foot", "clearance", "rate") if getattr(args, name, None) is not None]
    where = f"{source.robot.path}: geometry and gait" if source.robot is not None else "the leg"
    return where + (f" with {', '.join(flags)}" if flags else "")


@dataclass(frozen=True)
class FileWalk:
    """A trajectory file walked as it is (``walk --trajectory``): its heel strikes (the file's, or found from
    the feet) stand for the plan."""

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
    trajectory = Trajectory.load(file_option(args.trajectory, "--trajectory"))
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
        check_rate_option(source.robot, rate, f"--trajectory {args.trajectory}: its {rate:.4g} Hz")
    settings = WalkSettings(source.settings.cycle_s, rate, source.settings.clearance)
    # a CSV carries no heel strikes: find them from the feet, as plot and eigen fit do (footfall.py)
    strikes = tuple(trajectory.heel_strikes) or tuple(detect_heel_strikes(trajectory, source.geometry))
    return GaitSource(source.geometry, settings, source.max_step_m, source.robot), FileWalk(strikes), trajectory


def build_balanced_walk(args, source: GaitSource) -> BalancedPlan:
    """The balanced walk of a robot whose legs roll: its steps, with --cycle, --rate, --max-step and
    --clearance over the config's [gait]; the servos' speed fitted (gaitbot.gait.balance.speed_fit)."""
    return balanced_plan(source, step_lengths(args, source), args.max_step)


def balanced_plan(source: GaitSource, steps, max_step_m: float | None = None) -> BalancedPlan:
    """The balanced walk of these steps with the source's settings, as ``gaitbot generate`` walks them: the
    walker's longest step (its swing shapes) is --max-step, else the robot's default step, or the longest
    step asked for (``gaitbot eigen synth`` starts and stops its walks with the same walks)."""
    longest = max([max_step_m or source.default_step_m or 0.0, *steps])
    gait = balanced_gait_settings(source.robot, cycle_s=source.settings.cycle_s, rate_hz=source.settings.rate_hz,
                                  max_step_m=longest, clearance_m=source.settings.clearance)
    return plan_balanced(source.robot, steps, gait)


def speed_fit_note(plan: BalancedPlan) -> str | None:
    """One line when a balanced walk's settings were relaxed to fit the servos' speed (else None)."""
    fit = plan.fit
    if fit.relaxed == 0:
        return None
    b, g = fit.balance, fit.gait
    return (f"the servos' max_velocity_dps ({fit.limit_dps:g}) needed a gentler walk at this cycle and step: crouch "
            f"{b.crouch_knee_deg:g} deg, double support {100 * b.double_support_share:g}%, progression done at "
            f"{100 * b.progression_end:g}% of the swing, clearance {1000 * g.clearance_m:g} mm (peak "
            f"{fit.peak_dps:.0f} deg/s; docs/balance.md)")


def trajectory_for_robot(args, goals: bool = False) -> tuple[GaitSource, OnlineWalker, Trajectory]:
    """The walk the options ask for: (where its settings come from, its walker, its trajectory). A
    balanced walk's trajectory holds the planned angles, or with ``goals`` the angles its servos are sent
    (servo-sag feedforward included); a planar walk's are the same."""
    if getattr(args, "trajectory", None) is not None:
        return trajectory_file_walk(args)
    if steer_requested(args):
        return steered_walk(args, goals)
    if getattr(args, "terrain", None) is not None:
        source = gait_source(args)
        if source.balanced:
            raise UsageError(f"--terrain: robot {source.robot.name} walks with the balanced walker, which walks "
                             "on the flat only (terrain courses are walked by the planar walker)")
        source, walk = build_terrain_walk(args)
        return source, walk, pelvis_root(source, walk.trajectory)
    source = gait_source(args)
    if source.balanced:
        plan = build_balanced_walk(args, source)
        note = speed_fit_note(plan)
        if note:
            print(f"note: {note}", file=sys.stderr)
        return source, plan, plan.walk.trajectory(goals=goals)
    source, walker = build_walk(args)
    return source, walker, pelvis_root(source, trajectory_of(walker))


def pelvis_root(source: GaitSource, trajectory: Trajectory) -> Trajectory:
    """A sagittal walk's root is the hip point; a robot's root (its pelvis frame) may sit above the hips
    (``[geometry] hip_below_root_m``): lift it there, so the trajectory's root is the robot's."""
    lift = source.robot.geometry.hip_below_root_m if source.robot is not None else 0.0
    if lift == 0.0:
        return trajectory
    return replace(trajectory, root_m=trajectory.root_m + [0.0, 0.0, lift])


def build_terrain_walk(args):
    """Footholds, pelvis search and trajectory for ``--terrain FILE`` (seed 003 joined to the flat walker)."""
    source = gait_source(args)
    course = load_course(file_option(args.terrain, "--terrain"))
    settings = terrain_settings(source, course, getattr(args, "clearance", None))
    try:
        with progress(f"planning {Path(course.path).name}", unit="step") as bar:
            walk = plan_terrain_walk(make_context(source.geometry, source.settings), course.terrain, course.start_m,
                                     course.end_m, settings, source.max_step_m, on_progress=callback(bar))
    except CourseError as exc:
        raise UsageError(f"{course.path}: {exc}") from None
    except GaitGenerationError as exc:
        raise GaitGenerationError(f"{course.path}: {exc}") from None
    return source, walk
