"""``gaitbot eigen fit`` and ``gaitbot eigen synth``: wiring from files and a robot to gaitbot.gait.eigen.

fit: each EXAMPLE is a trajectory file (.npz with heel strikes, or .csv whose heel strikes are
found from foot contact with the robot's leg); its steady cycles are examples, labelled with the
walk's step length. The examples are walks of one robot: every file holds the joints the robot walks
with (gait/eigen/legs.py: the six pitch joints, or all twelve leg joints of a robot whose legs roll)
and its root stands where that robot's legs put it; a file that differs is refused, naming it and
what differs (files do not name their robot, so its legs are how it is told). Prints the variance
explained per pose axis and per eigen-motion (pose.py says how many pose axes are kept and why); warns
about example files that break the robot's limits.

synth: a walk at ``--step-length`` (optionally going to ``--to-step-length``), written in the
trajectory format with the model's joints and the root from foot contact; optionally forced through
``--pose-deg`` (one angle per joint of the model, in its order) at ``--pose-time`` seconds into each
synthesised cycle (Li et al. 2009 eq. 13). The walk starts standing and ends standing: the robot's own
walker's first steps, the synthesised cycles, its closing step (see gait/eigen/synth.py).
The walk is checked as ``gaitbot walk`` would check it, limits and (for a robot not on a boom)
balance: one that fails (a forced pose far from the examples' at that time can distort the whole
cycle; an eigen-synthesised walk is not balanced by construction) is still written, for plotting,
but a warning says so and the exit status is 1.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from gaitbot.app.arguments import add_command, leg_options, robot_options
from gaitbot.gait.eigen import (EigenGaitModel, EigenModelError, FitOptions, PlanarLegs, SpatialLegs, WalkEnds,
                                cycles_from_trajectory, fit_model, synthesize_walk, walk_label)
from gaitbot.gait.footfall import CONTACT_TOL_FRACTION
from gaitbot.gait.trajectory import MAX_ANGLE_DEG, Trajectory
from gaitbot.app.options import UsageError, gait_source, load_robot
from gaitbot.app.outputs import output_path, write_output
from gaitbot.app.progress import callback, progress
from gaitbot.app.planned_walk import balanced_plan
from gaitbot.check.preflight import preflight
from gaitbot.errors import UserError
from gaitbot.robot.config import shipped_config_names
from gaitbot.robot.origin import origin_for
from gaitbot.robot.walk_settings import GaitSource, walk_settings

POSE_TOL_DEG = 0.1
#: Synthesised cycles one `eigen synth` may ask for (each two steps).
MAX_CYCLES = 500


def add_parser(subparsers):
    """``eigen`` and its own subcommands ``eigen fit`` and ``eigen synth`` (``parser.commands``)."""
    p = add_command(subparsers, "eigen")
    eigen = p.add_subparsers(dest="eigen_command", required=True, metavar="{fit,synth}")
    q = add_command(eigen, "eigen fit")
    q.add_argument("examples", nargs="+", help="trajectory files (.npz or .csv), one walk each")
    q.add_argument("-o", "--output", required=True, help="model file, e.g. model.npz")
    robot_options(q, "robot config whose leg walked the examples (default xl430-biped); the model remembers it")
    leg_options(q, "when the examples were walked with another leg than the robot's; the model remembers it")
    q.add_argument("--samples", type=int, default=100, help="samples per resampled cycle (default 100)")
    q.add_argument("--basis", choices=("fourier", "bspline"), default="fourier",
                   help="functions the cycles are fitted with: fourier for periodic walking (default), bspline for "
                   "motion that does not repeat")
    q.add_argument("--n-basis", type=int, default=31, help="basis functions per channel (odd for fourier; default 31)")
    q.add_argument("--roughness", type=float, default=0.0,
                   help="penalty on the fitted curves' second derivative: larger is smoother (default 0)")
    q.add_argument("--pose-variance", type=float, default=0.95, metavar="SHARE",
                   help="share of the pose variance the pose PCA keeps at least (default 0.95)")
    q.add_argument("--pose-tolerance-deg", type=float, default=0.5, metavar="DEG",
                   help="and more pose axes until no example pose moves by more than this when projected "
                   "(default 0.5; inf: the variance rule alone)")
    q.add_argument("--variance", type=float, default=0.95, metavar="SHARE",
                   help="share of the variance the eigen-motions kept explain (default 0.95)")
    q.add_argument("--components", type=int, metavar="N", help="keep exactly this many eigen-motions")
    q.add_argument("--align", choices=("dtw", "none"), default="dtw",
                   help="time alignment of the cycles: dynamic time warping (default) or none")
    q.add_argument("--label-degree", type=int, default=2, metavar="N",
                   help="degree of the polynomial that maps step length to the model's coefficients (default 2)")
    r = add_command(eigen, "eigen synth")
    r.add_argument("model", help="model file from gaitbot eigen fit")
    r.add_argument("--step-length", type=float, required=True, metavar="M", help="step length in metres")
    r.add_argument("--to-step-length", type=float, metavar="M",
                   help="change the step length smoothly to this over the cycles")
    r.add_argument("--cycles", type=int, default=3, help="synthesised cycles (two steps each; default 3)")
    r.add_argument("--components", type=int, metavar="N", help="eigen-motions to use (default: those the model kept)")
    r.add_argument("--pose-deg", metavar="DEG,DEG,...",
                   help="the pose the motion must pass through: one angle in degrees per joint of the model, in its "
                   "order (eigen fit prints it; six pitch joints: hip, knee, ankle left, then right); write "
                   "--pose-deg=-5,... when the first is negative")
    r.add_argument("--pose-time", type=float, metavar="S", help="seconds into each synthesised cycle for --pose-deg")
    robot_options(r, "robot config (default: the robot the model was fitted for)")
    leg_options(r, "must be the leg the model was fitted with")
    r.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")
    p.commands = {"eigen fit": q, "eigen synth": r}
    return p


def run(args) -> int:
    return {"fit": run_fit, "synth": run_synth}[args.eigen_command](args)


#: Example files within this share of the robot's frame rate were sampled at it (CSV times carry
#: 9 significant digits, so a 60 Hz file reads back as 60.0000001 Hz).
RATE_TOL = 1e-6


#: A file's root may sit this far (median over its frames, as a share of the leg) from where the robot's legs
#: put it with a sole on the floor: a file written for this robot is within a micrometre (the contact rule
#: is the walker's own), a shipped robot's walk read with another shipped robot's legs 30 mm or more off.
LEG_FIT_TOL_FRACTION = 5 * CONTACT_TOL_FRACTION


def robot_legs(source: GaitSource, config):
    """The legs the examples of ``config`` walk on (gait/eigen/legs.py): 3D for a robot whose legs roll,
    else planar with the leg of ``source`` (the robot's, or --thigh/--shank/--foot)."""
    if config.is_3d:
        return SpatialLegs(config.body.geometry)
    lift = config.geometry.hip_below_root_m if source.robot is not None else 0.0
    return PlanarLegs(source.geometry, lift)


def _joint_list(joints) -> str:
    return f"{len(joints)} joints ({', '.join(joints)})"


def robots_walking_with(joints) -> list[str]:
    """The shipped robots whose walker moves exactly these joints (a hint for a file of another robot)."""
    names = []
    for name in shipped_config_names():
        try:
            config = load_robot(name)
        except UserError:
            continue
        if (SpatialLegs.joints if config.is_3d else PlanarLegs.joints) == tuple(joints):
            names.append(name)
    return names


def _another_robot_hint(joints) -> str:
    names = robots_walking_with(joints)
    return f"give the robot that walked them with --robot ({', '.join(names)} walk with these joints)" if names \
        else "give the robot that walked them with --robot"


def check_example(path, trajectory: Trajectory, legs, who: str, first: tuple | None) -> None:
    """One example file against the first one and the robot's legs: the same joints, the robot's joints, an
    upright torso, the root where the legs put it; else one line naming the file and what differs."""
    joints = tuple(trajectory.joints)
    if first is not None and joints != first[1]:
        raise UsageError(f"{path} holds {_joint_list(joints)}, {first[0]} holds {_joint_list(first[1])}: the "
                         f"examples must be walks of one robot, with the same joints")
    if joints != tuple(legs.joints):
        raise UsageError(f"{path} holds {_joint_list(joints)}; {who} walks with {_joint_list(legs.joints)}: "
                         f"were the examples walked by another robot? {_another_robot_hint(joints)}")
    if trajectory.torso_rpy_rad is not None and np.any(trajectory.torso_rpy_rad != 0):
        raise UsageError(f"{path} turns the torso (its torso_roll/pitch/yaw columns): eigen-gaits learn walks "
                         f"with an upright torso, whose root follows from the feet")
    off = legs.root_height_error_m(trajectory)
    if off > LEG_FIT_TOL_FRACTION * legs.leg_geometry.leg_length:
        raise UsageError(f"{path}: its root is {1000 * off:.1f} mm above or below where {who}'s legs put it with a "
                         f"sole on the floor (median over its frames): were the examples walked by another robot "
                         f"or leg? {_another_robot_hint(joints)}, or the leg with --thigh/--shank/--foot")


def load_examples(paths, legs, robot_rate_hz: float | None = None, config=None, done=lambda n: None,
                  who: str = "the robot"):
    """Example cycles of every file, each labelled with its walk's step length; and the frame rate
    (the robot's own when the files were sampled at it). Every file must be a walk of the robot ``who``
    on ``legs`` (``check_example``) at the first file's frame rate. With ``config``, a file that breaks
    the robot's limits (a recording a hand took too far) is learnt from, with a warning on stderr.
    ``done(1)`` is called after each file (a progress bar)."""
    examples, first = [], None
    for path in paths:
        trajectory = Trajectory.load(path)
        check_example(path, trajectory, legs, who, first)
        rate = 1.0 / float(np.median(np.diff(trajectory.t_s)))
        if first is None:
            first = (path, tuple(trajectory.joints), rate)
        elif abs(rate - first[2]) > RATE_TOL * max(rate, first[2]):
            raise UsageError(f"{path} is sampled at {rate:g} Hz, {first[0]} at {first[2]:g} Hz: the example files "
                             f"have different frame rates")
        if config is not None:
            report = preflight(config, trajectory)
            if not report.ok:
                print(f"warning: {path}: {report.first_error}; it is learnt from as it is, but walks synthesised "
                      f"near it may break the same limit, and gaitbot walk refuses those", file=sys.stderr)
        cycles = cycles_from_trajectory(trajectory, legs, source=str(path))
        label = walk_label(cycles)
        examples += [c.__class__(c.angles_rad, c.duration_s, c.right_strike_phase, label, c.source) for c in cycles]
        done(1)
    if robot_rate_hz is not None and abs(first[2] - robot_rate_hz) <= RATE_TOL * robot_rate_hz:
        return examples, float(robot_rate_hz)
    return examples, first[2]


def run_fit(args) -> int:
    out = Path(args.output)
    if out.suffix != ".npz":
        raise UsageError(f"-o {out}: the model file must end in .npz")
    output_path(out, "-o", args)
    source = gait_source(args)
    config = load_robot(args.robot, getattr(args, "calibration", None))
    refuse_leg_options_for_3d(args, config)
    legs = robot_legs(source, config)
    options = FitOptions(samples=args.samples, basis=args.basis, n_basis=args.n_basis, roughness=args.roughness,
                         pose_variance=args.pose_variance, pose_tolerance_deg=args.pose_tolerance_deg,
                         motion_variance=args.variance, components=args.components, align=args.align,
                         label_degree=args.label_degree)
    with progress("eigen fit: reading examples", total=len(args.examples), unit="file") as bar:
        examples, rate = load_examples(args.examples, legs, config.gait.rate_hz, source.robot, bar.update,
                                       who=config.name if source.robot is not None else "this leg")
    with progress("eigen fit: aligning cycles (DTW)", total=len(examples), unit="cycle") as bar:
        model = fit_model(examples, source.geometry, rate, options, periodic=args.basis == "fourier", robot=config.name,
                          on_progress=callback(bar), legs=legs)
    write_output(out, model.save)
    labels = sorted(set(np.round(model.labels, 6)))
    print(f"wrote {out}: {len(examples)} example cycles from {len(args.examples)} files, step lengths "
          f"{', '.join(f'{v:g}' for v in labels)} m; for {config.name}, {describe_leg(source.geometry)}")
    print(f"joints ({len(model.joints)}, the order of --pose-deg): {', '.join(model.joints)}; root from foot "
          f"contact in {', '.join(model.root_axes)}")
    print_pose_pca(model, options)
    print_variance_table("eigen-motion", model.variance_explained, model.n_components)
    cumulative = np.cumsum(model.variance_explained)
    print(f"{model.n_components} eigen-motions kept ({100 * cumulative[model.n_components - 1]:.2f}% of the variance)")
    return 0


def refuse_leg_options_for_3d(args, config) -> None:
    """--thigh/--shank/--foot change a planar leg; a robot whose legs roll walks on its own body."""
    given = [f"--{k}" for k in ("thigh", "shank", "foot") if getattr(args, k, None) is not None]
    if given and config.is_3d:
        raise UsageError(f"{'/'.join(given)}: {config.name} walks with the balanced walker on its own legs "
                         f"([geometry] of its config); another leg is for the pitch-only robots")


def describe_leg(g) -> str:
    return f"leg {1000 * g.thigh:.0f} / {1000 * g.shank:.0f} / {1000 * g.foot:.0f} mm (thigh / shank / foot)"


def print_variance_table(what: str, shares: np.ndarray, kept: int) -> None:
    """Variance explained per component (percent) and cumulative, the kept ones marked."""
    print(f"{what:>12}  variance %  cumulative %")
    for i, (share, total) in enumerate(zip(shares, np.cumsum(shares)), start=1):
        print(f"{i:12d}  {100 * share:10.3f}  {100 * total:12.3f}{'  kept' if i <= kept else ''}")


def print_pose_pca(model: EigenGaitModel, options: FitOptions) -> None:
    shares = model.pose_eigenvalues / model.pose_eigenvalues.sum()
    print_variance_table("pose axis", shares, model.pose_dims)
    d, by_variance, residuals = model.pose_dims, model.pose_variance_dims, model.pose_residuals_deg
    kept = 100 * shares[:d].sum()
    line = (f"pose PCA: {d} of {len(shares)} axes kept ({kept:.2f}% of the pose variance; the examples' poses "
            f"move by at most {residuals[d - 1]:.3f} deg when projected on them)")
    if d > by_variance:
        line += (f"; {100 * options.pose_variance:g}% of the variance needs only {by_variance}, which would move a "
                 f"joint by up to {residuals[by_variance - 1]:.2f} deg, more than --pose-tolerance-deg "
                 f"{options.pose_tolerance_deg:g}")
    print(line)


def _parse_pose(text: str, joints) -> np.ndarray:
    """--pose-deg: one angle in degrees per joint of the model, in the model's order."""
    items = text.split(",")
    if len(items) != len(joints):
        raise UsageError(f"--pose-deg: give {len(joints)} angles in degrees ({', '.join(joints)}), "
                         f"got {len(items)}")
    try:
        values = np.array([float(v) for v in items])
    except ValueError:
        raise UsageError(f"--pose-deg: {text!r} holds a value that is not a number") from None
    if not np.all(np.isfinite(values)):
        raise UsageError("--pose-deg: every angle must be a finite number of degrees")
    return values


def _check_pose_limits(config, joints, pose_deg: np.ndarray) -> None:
    """Each angle against its joint's limits by name (a held joint: its hold angle)."""
    limits = {j.name: (j.hold_deg, j.hold_deg) if j.hold_deg is not None else (j.min_deg, j.max_deg)
              for j in config.joints}
    for name, value in zip(joints, pose_deg):
        if name not in limits:
            raise UsageError(f"--pose-deg: {config.name} has no joint {name}")
        lo, hi = limits[name]
        if not (lo <= value <= hi):
            raise UsageError(f"--pose-deg: {name} {value:g} deg is outside its joint limits {lo:g} to {hi:g} deg "
                             f"({config.name})")


def model_robot(args, model: EigenGaitModel, model_path: str):
    """The robot to synthesise for: the model's own (``--robot`` may only name it again), with the leg the
    model learnt; another robot or leg is refused in one line."""
    if args.robot is None and model.robot:
        try:
            config = load_robot(model.robot, getattr(args, "calibration", None))
        except UserError:
            raise UsageError(f"{model_path} was fitted for {model.robot}, which is not a shipped robot: give its "
                             f"config with --robot") from None
    else:
        config = load_robot(args.robot, getattr(args, "calibration", None))
    if model.robot and config.name != model.robot:
        raise UsageError(f"{model_path} was fitted for {model.robot}, not {config.name}: fit a model on "
                         f"{config.name}'s walks (gaitbot eigen fit --robot {config.name})")
    refuse_leg_options_for_3d(args, config)
    source = gait_source(argparse.Namespace(robot=str(config.path), calibration=getattr(args, "calibration", None),
                                            thigh=args.thigh, shank=args.shank, foot=args.foot))
    legs = robot_legs(source, config)
    if tuple(model.joints) != tuple(legs.joints):
        raise UsageError(f"{model_path} learnt {_joint_list(model.joints)}; {config.name} walks with "
                         f"{_joint_list(legs.joints)}: fit a model on {config.name}'s walks "
                         f"(gaitbot eigen fit --robot {config.name})")
    if source.geometry != model.geometry or getattr(legs, "body_geometry", None) != model.body_geometry:
        raise UsageError(f"{model_path} learnt a {describe_leg(model.geometry)}, this is a "
                         f"{describe_leg(source.geometry)}"
                         + (" (or its hip, sole or foot width differ)" if source.geometry == model.geometry else "")
                         + ": give the model's leg with --thigh/--shank/--foot, or fit a model on walks of this leg")
    return config, source, legs


def walk_ends(config, source: GaitSource):
    """The robot's own walker for a synthesised walk's start and stop (gait/eigen/synth.py WalkEnds): the
    balanced walker for a robot whose legs roll, with as many steps that its preview, which looks
    preview_horizon_s ahead, does not see the stop at the first left heel strike (None: the planar walker)."""
    if not config.is_3d:
        return None
    steps = 2 + 2 * math.ceil(config.balance.preview_horizon_s / source.settings.cycle_s)
    return WalkEnds(lambda step_m, n: balanced_plan(source, [step_m] * n).walk.trajectory(), steps, join_order=2)


def _forced_pose(args, model, config, components):
    """``--pose-deg`` at ``--pose-time``: the eigen-motions' weights that take every cycle through the pose
    (one per cycle, and one for the walk's end) and (the pose time, the worst joint's miss in deg); (None,
    None) without --pose-deg."""
    if args.pose_deg is None:
        return None, None
    if args.pose_time is None:
        raise UsageError("--pose-deg needs --pose-time (seconds into each synthesised cycle)")
    if args.to_step_length is not None:
        raise UsageError("--pose-deg forces every cycle through one pose: leave out --to-step-length")
    pose_deg = _parse_pose(args.pose_deg, model.joints)
    _check_pose_limits(config, model.joints, pose_deg)
    duration, warp, _ = model.timing_for(args.step_length)
    if not (0.0 <= args.pose_time < duration):
        raise UsageError(f"--pose-time must be from 0 to below the cycle's {duration:.4g} s, got {args.pose_time:g}")
    s_prime = float(model.aligned_phase(args.pose_time / duration, warp))
    alpha, miss = model.through_pose(np.radians(pose_deg), s_prime, model.coefficients_for(args.step_length, components))
    worst = float(np.degrees(np.abs(miss)).max())
    if worst > POSE_TOL_DEG:
        j = int(np.argmax(np.abs(miss)))
        hint = f"try --components up to {len(model.eigenvalues)}"
        if model.pose_dims < len(model.joints):
            hint += ", or fit with a smaller --pose-tolerance-deg (more pose axes)"
        raise EigenModelError(f"--pose-deg cannot be reached: the model's {len(alpha)} eigen-motions and "
                              f"{model.pose_dims} pose axes miss {model.joints[j]} by {worst:.3g} deg ({hint})")
    return [alpha] * (args.cycles + 1), (args.pose_time, worst)


def run_synth(args) -> int:
    out = Path(args.output)
    if out.suffix not in (".csv", ".npz"):
        raise UsageError(f"-o {out}: the output must end in .csv or .npz")
    output_path(out, "-o", args)
    if not 1 <= args.cycles <= MAX_CYCLES:
        raise UsageError(f"--cycles must be 1..{MAX_CYCLES}, got {args.cycles}")
    if args.pose_time is not None and args.pose_deg is None:
        raise UsageError("--pose-time: only with --pose-deg (the pose to pass through at that time)")
    if args.pose_time is not None and not math.isfinite(args.pose_time):
        raise UsageError(f"--pose-time must be a finite number of seconds, got {args.pose_time!r}")
    for name in ("step_length", "to_step_length"):
        value = getattr(args, name)
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise UsageError(f"--{name.replace('_', '-')} must be a finite number of metres, 0 or more, got {value:g}")
    model = EigenGaitModel.load(args.model)
    config, source, legs = model_robot(args, model, args.model)
    settings = walk_settings(config)
    for name in ("step_length", "to_step_length"):
        value = getattr(args, name)
        if value is not None and not math.isfinite(value):
            raise UsageError(f"--{name.replace('_', '-')} must be a finite number of metres, got {value!r}")
    if args.step_length > config.gait.max_step_m or (args.to_step_length or 0) > config.gait.max_step_m:
        raise UsageError(f"step lengths must be at most max_step_m = {config.gait.max_step_m:g} m ({config.name})")
    components = args.components
    if components is not None and not (1 <= components <= len(model.eigenvalues)):
        raise UsageError(f"--components {components}: the model has {len(model.eigenvalues)} eigen-motions "
                         f"(fit with more example walks for more)")
    alphas, pose_report = _forced_pose(args, model, config, components)
    try:
        walk = synthesize_walk(model, settings, args.step_length, args.to_step_length, cycles=args.cycles,
                               components=components, alphas=alphas, ends=walk_ends(config, source), legs=legs)
        with np.errstate(all="ignore"):
            angles_deg = np.degrees(walk.angles_rad)
            finite = all(np.all(np.isfinite(a)) for a in (walk.t_s, angles_deg, walk.root_m))
        if not finite or np.abs(angles_deg).max() > MAX_ANGLE_DEG:
            raise ValueError(f"an angle is not a finite number within +-{MAX_ANGLE_DEG:g} deg")
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, UserError):
            raise
        raise UsageError(f"{args.model}: this model does not synthesise a walk of finite angles "
                         f"({' '.join(str(exc).split())}); fit it again with `gaitbot eigen fit`") from None
    walk = replace(walk, origin=origin_for(config))  # the file remembers its robot
    write_output(out, walk.save)
    xs = [h.x_m for h in walk.heel_strikes]
    # the last heel strike is the walker's closing step: the trailing foot set down beside the leading one
    # (a step of about 0, which the root rebuilt from contact can put a fraction of a millimetre behind)
    steps = np.diff(xs)[:-1]
    print(f"wrote {out}: {len(walk)} frames, {walk.t_s[-1]:.2f} s, {len(xs)} heel strikes, "
          f"{walk.root_m[-1, 0] - walk.root_m[0, 0]:.4f} m; step lengths between heel strikes "
          f"{', '.join(f'{d:.4f}' for d in steps)} m, then the trailing foot closes beside the leading one")
    if pose_report is not None:
        starts = [h.t_s for h in walk.heel_strikes if h.leg == "left"][:args.cycles]
        times = ", ".join(f"{t + pose_report[0]:.3f}" for t in starts)
        print(f"pose reached to {pose_report[1]:.3g} deg at t = {times} s")
    report = preflight(config, walk)
    if not report.ok:
        # a forced pose far from the examples' poses at that time can take every other frame far off
        print(f"warning: {out} fails {config.name}'s check ({report.first_error}); gaitbot walk would refuse it. "
              f"Ask for a pose nearer the examples' at that time, or fewer --components", file=sys.stderr)
        return 1
    return 0
