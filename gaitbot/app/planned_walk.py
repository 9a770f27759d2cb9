"""One plan from the command line: the walk options read once into a :class:`WalkRequest`, planned by its
gait source into one :class:`PlannedWalk`, for ``plan``, ``generate`` and ``walk``.

The robot is loaded once (``walk_request``). Which gait source plans the walk is decided in one place
(``gait_source_of``), and each source is one function from the request to a PlannedWalk (``PLANNERS``):
a steady planar walk of given steps, a terrain course, a trajectory file, and for robots whose legs roll
the balanced walk. A new source (a velocity-command walk) is one more planner there and the options
that ask for it; the commands that preflight, stream, write or summarise a walk need no change.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from gaitbot.app.options import UsageError, check_rate_option, file_option, gait_source, step_lengths
from gaitbot.app.progress import callback, progress
from gaitbot.app.steer_options import steer_requested
from gaitbot.gait.footfall import detect_heel_strikes
from gaitbot.gait.step_length import StepLengthError
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.terrain.footholds import CourseError
from gaitbot.gait.terrain.walk import plan_terrain_walk
from gaitbot.gait.trajectory import Trajectory
from gaitbot.gait.walk_segments import GaitGenerationError
from gaitbot.gait.walker import WalkSettings, make_context, plan_walk, trajectory_of
from gaitbot.robot.balanced_walk import BalancedPlan, balanced_gait_settings, plan_balanced
from gaitbot.robot.config import RobotConfig
from gaitbot.robot.planar_fit import fit_cycle
from gaitbot.robot.walk_settings import GaitSource, terrain_settings


@dataclass(frozen=True)
class WalkRequest:
    """What the command line asks to walk: ``source`` (the robot, loaded once, and the leg and walk settings
    after ``--thigh``, ``--rate``, ``--cycle`` ...), the gait source that plans it (a key of PLANNERS), and
    the parsed options, which that gait source reads for its own inputs (steps, a course, a file)."""

    source: GaitSource
    gait: str
    options: argparse.Namespace


@dataclass(frozen=True)
class PlannedWalk:
    """A walk planned whole, whatever planned it.

    goals: the angles the servos are sent (a balanced walk's servo-sag feedforward included);
    planned: the angles the body is planned to move through (the same trajectory for the planar walks);
    heel_strikes / planned_steps: the plan's heel strikes, and its steps (for a trajectory file, its heel
    strikes); plan: the gait source's own plan (OnlineWalker, TerrainWalk, BalancedPlan, FileWalk), for
    what only that source can say (``gaitbot plan``'s tables, the simulation's swing windows).
    """

    source: GaitSource
    goals: Trajectory
    planned: Trajectory
    heel_strikes: tuple
    planned_steps: tuple
    plan: object
    notes: tuple[str, ...] = ()  # what the planner had to change or could not keep (said once all checks passed)

    def say_notes(self) -> None:
        """The planner's notes on stderr, one ``note:`` line each: a command says them once its checks passed,
        so that a refusal stays one line."""
        for note in self.notes:
            print(f"note: {note}", file=sys.stderr)

    @property
    def rate_hz(self) -> float:
        return self.source.settings.rate_hz


def walk_request(args: argparse.Namespace, robot: RobotConfig | None = None) -> WalkRequest:
    """The request of the walk options; ``robot``: the robot config already loaded by the command (else it is
    loaded here, once)."""
    if getattr(args, "trajectory", None) is not None and getattr(args, "rate", None) is not None:
        raise UsageError("--rate: a trajectory file is walked at its own frame rate; leave --rate out")
    source = gait_source(args, robot)
    return WalkRequest(source, gait_source_of(args, source), args)


def gait_source_of(args: argparse.Namespace, source: GaitSource) -> str:
    """Which gait source plans the walk the options ask for."""
    if getattr(args, "trajectory", None) is not None:
        return "trajectory"
    if getattr(args, "terrain", None) is not None:
        return "terrain"
    if steer_requested(args):
        return "steered"
    return "balanced" if source.balanced else "planar"


def plan_request(request: WalkRequest) -> PlannedWalk:
    """The walk of the request, planned by its gait source."""
    return PLANNERS[request.gait](request)


def planned_walk(args: argparse.Namespace, robot: RobotConfig | None = None) -> PlannedWalk:
    """The walk the options ask for (``walk_request`` then ``plan_request``)."""
    return plan_request(walk_request(args, robot))


# --------------------------------------------------------------------------- the gait sources

def plan_planar(request: WalkRequest) -> PlannedWalk:
    """``--steps`` / ``--distance`` on a planar robot (or a leg given on the command line): the Boulic walker."""
    source, args = request.source, request.options
    steps = step_lengths(args, source)

    def plan(settings):
        walker = plan_walk(source.geometry, steps, settings)
        return walker, pelvis_root(source, trajectory_of(walker))

    try:  # the cycle stretched where the servos' limits need it (gaitbot.robot.planar_fit)
        fit = fit_cycle(source.robot, source.settings, plan)
    except StepLengthError as exc:
        raise UsageError(str(exc)) from None
    except GaitGenerationError as exc:
        raise UsageError(f"{leg_origin(args, source)}: {exc}") from None
    walker, trajectory = fit.plan, fit.trajectory
    if fit.stretched:
        source = replace(source, settings=replace(source.settings, cycle_s=fit.cycle_s))
    return PlannedWalk(source, trajectory, trajectory, tuple(walker.heel_strikes), tuple(walker.planned_steps), walker,
                       _notes(fit.note()))


def plan_balanced_walk(request: WalkRequest) -> PlannedWalk:
    """``--steps`` / ``--distance`` on a robot whose legs roll: the balanced walk, its servos' speed fitted
    (gaitbot.gait.balance.speed_fit; said in a note when the walk had to be gentler)."""
    source, args = request.source, request.options
    plan = balanced_plan(source, step_lengths(args, source), args.max_step)
    return PlannedWalk(source, plan.walk.trajectory(goals=True), plan.walk.trajectory(), tuple(plan.heel_strikes),
                       tuple(plan.planned_steps), plan, _notes(speed_fit_note(plan)))


def plan_terrain(request: WalkRequest) -> PlannedWalk:
    """``--terrain FILE``: footholds, pelvis search and trajectory (Zhang 2008 joined to the flat walker)."""
    source, args = request.source, request.options
    if source.balanced:
        raise UsageError(f"--terrain: robot {source.robot.name} walks with the balanced walker, which walks "
                         "on the flat only (terrain courses are walked by the planar walker)")
    def plan(settings):
        walk = terrain_walk(replace(source, settings=settings), args.terrain, getattr(args, "clearance", None))
        return walk, pelvis_root(source, walk.trajectory)

    fit = fit_cycle(source.robot, source.settings, plan)  # the cycle stretched where the servos' limits need it
    walk, trajectory = fit.plan, fit.trajectory
    if fit.stretched:
        source = replace(source, settings=replace(source.settings, cycle_s=fit.cycle_s))
    return PlannedWalk(source, trajectory, trajectory, tuple(walk.heel_strikes), tuple(walk.planned_steps), walk,
                       _notes(fit.note()))


def plan_trajectory_file(request: WalkRequest) -> PlannedWalk:
    """``--trajectory FILE``: the file streamed frame by frame at its own (uniform) rate, which the bus must
    carry; its heel strikes (the file's, or found from the feet) stand for the plan."""
    source, args = request.source, request.options
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
    source = GaitSource(source.geometry, settings, source.max_step_m, source.robot)
    return PlannedWalk(source, trajectory, trajectory, strikes, strikes, FileWalk(strikes))


def plan_steered_walk(request: WalkRequest) -> PlannedWalk:
    """``--velocity``/``--duration`` or ``--commands`` on a robot whose legs roll and turn: the footstep
    planner's steps walked by the balanced walker (gaitbot.app.steer_walk, docs/steering.md), its servos'
    speed fitted as a straight walk's (said in the same note)."""
    from gaitbot.app.steer_walk import steered_plan

    plan = steered_plan(request.source, request.options)
    return PlannedWalk(request.source, plan.walk.trajectory(goals=True), plan.walk.trajectory(),
                       tuple(plan.heel_strikes), tuple(plan.planned_steps), plan, _notes(speed_fit_note(plan)))


#: Gait source -> its planner (gait_source_of says which the options ask for).
PLANNERS: dict[str, Callable[[WalkRequest], PlannedWalk]] = {
    "planar": plan_planar, "balanced": plan_balanced_walk, "terrain": plan_terrain, "trajectory": plan_trajectory_file,
    "steered": plan_steered_walk,
}


# --------------------------------------------------------------------------- what the sources share

def _notes(*notes: str | None) -> tuple[str, ...]:
    return tuple(n for n in notes if n)


@dataclass(frozen=True)
class FileWalk:
    """A trajectory file walked as it is (``walk --trajectory``): its heel strikes stand for the plan."""

    heel_strikes: tuple

    @property
    def planned_steps(self) -> tuple:
        return self.heel_strikes


#: A trajectory file's sample times must be this close to one period apart (share of the period).
UNIFORM_RATE_TOL = 1e-3


def leg_origin(args, source: GaitSource) -> str:
    """Where the leg and gait settings of a walk come from, for a message about a walk they cannot make."""
    flags = [f"--{name}" for name in ("thigh", "shank", "foot", "clearance", "rate") if getattr(args, name, None) is not None]
    where = f"{source.robot.path}: geometry and gait" if source.robot is not None else "the leg"
    return where + (f" with {', '.join(flags)}" if flags else "")


def pelvis_root(source: GaitSource, trajectory: Trajectory) -> Trajectory:
    """A sagittal walk's root is the hip point; a robot's root (its pelvis frame) may sit above the hips
    (``[geometry] hip_below_root_m``): lift it there, so the trajectory's root is the robot's."""
    lift = source.robot.geometry.hip_below_root_m if source.robot is not None else 0.0
    if lift == 0.0:
        return trajectory
    return replace(trajectory, root_m=trajectory.root_m + [0.0, 0.0, lift])


def balanced_plan(source: GaitSource, steps, max_step_m: float | None = None) -> BalancedPlan:
    """The balanced walk of these steps with the source's settings, as ``gaitbot generate`` walks them: the
    walker's longest step (its swing shapes) is --max-step, else the robot's default step, or the longest
    step asked for (``gaitbot eigen synth`` starts and stops its walks with the same walks)."""
    longest = max([max_step_m or source.default_step_m or 0.0, *steps])
    gait = balanced_gait_settings(source.robot, cycle_s=source.settings.cycle_s, rate_hz=source.settings.rate_hz,
                                  max_step_m=longest, clearance_m=source.settings.clearance,
                                  clearance_asked=source.clearance_asked)
    return plan_balanced(source.robot, steps, gait)


def speed_fit_note(plan: BalancedPlan) -> str | None:
    """One line when a balanced walk's settings were relaxed to keep the servos' limits with the planning
    margin (PLANNED_SHARE, gaitbot.robot.motion_margin), or could not be (else None)."""
    fit = plan.fit
    if fit.relaxed == 0 and fit.fits:
        return None
    b, g = fit.balance, fit.gait
    settings = (f"crouch {b.crouch_knee_deg:g} deg, double support {100 * b.double_support_share:g}%, progression "
                f"done at {100 * b.progression_end:g}% of the swing, clearance {1000 * g.clearance_m:g} mm"
                + (" (as --clearance asked: kept, not lowered)" if fit.kept_clearance else ""))
    peak = f"peak {fit.peak_dps:.0f} deg/s, {100 * fit.peak_share:.1f}% of a limit"
    # a foot still travelling when it lands lands short (measured: docs/walk-faster.md)
    short = ("; with the foot moving until it lands, steps land short of the plan: a longer --cycle with longer "
             "steps goes further, docs/walk-faster.md" if b.progression_end >= 1.0 else "")
    if not fit.fits:
        return (f"no gentler walk keeps the servos within {100 * fit.target_share:g}% of their velocity and "
                f"acceleration limits (the margin planned walks keep) at this cycle and step: walking with "
                f"{settings} ({peak}; a longer --cycle or shorter steps fit; docs/checking.md){short}")
    return (f"the servos' limits (max_velocity_dps {fit.limit_dps:g}, kept within {100 * fit.target_share:g}%) needed "
            f"a gentler walk at this cycle and step: {settings} ({peak}; docs/balance.md){short}")


def clearance_hint(source: GaitSource) -> str:
    """Said with a balanced walk's limit refusal when ``--clearance`` was given: the speed fit kept it, where it
    lowers the robot's own clearance to fit the servos (gaitbot.gait.balance.speed_fit)."""
    if not (source.balanced and source.clearance_asked):
        return ""
    return (f" (--clearance {source.settings.clearance:g} m is kept as asked, not lowered to fit the servos: a "
            f"lower one, a longer --cycle or shorter steps may fit)")


def terrain_walk(source: GaitSource, course_path: str, clearance_m: float | None = None):
    """The terrain walker's walk of a course file for this leg (``gaitbot plot --terrain`` draws one too)."""
    course = load_course(file_option(course_path, "--terrain"))
    settings = terrain_settings(source, course, clearance_m)
    try:
        with progress(f"planning {Path(course.path).name}", unit="step") as bar:
            return plan_terrain_walk(make_context(source.geometry, source.settings), course.terrain, course.start_m,
                                     course.end_m, settings, source.max_step_m, on_progress=callback(bar))
    except CourseError as exc:
        raise UsageError(f"{course.path}: {exc}") from None
    except GaitGenerationError as exc:
        raise GaitGenerationError(f"{course.path}: {exc}") from None
