"""``gaitbot generate``: the trajectory of a walk, written as CSV or NPZ (docs/file-formats.md).

``--goals`` writes the goal angles a walk sends instead of the planned ones: for a balanced robot with
servo-sag feedforward, each planned angle plus its gravity torque over the servo's stiffness (exactly
what a dry-run recording of the same walk decodes to); for others the planned angles themselves.

What was written goes through ``gaitbot walk``'s preflight (gaitbot.check.preflight, the same as ``gaitbot
check``): the file as ``walk --trajectory`` would judge it, and the walk as ``walk`` with the same options
would. If ``walk`` would refuse either, the file is still written and generate exits 1 saying why in one line.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from gaitbot.app.arguments import add_command, check_walk_source, walk_options
from gaitbot.app.options import UsageError, walked_by
from gaitbot.app.outputs import output_path, write_output
from gaitbot.app.planned_walk import clearance_hint, planned_walk
from gaitbot.check.preflight import LimitBroken, preflight
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.trajectory import load_fast
from gaitbot.robot.origin import origin_for


def add_parser(subparsers):
    p = add_command(subparsers, "generate")
    walk_options(p)
    p.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz (file formats: docs/file-formats.md)")
    p.add_argument("--goals", action="store_true", help="write the goal angles a walk sends (servo-sag "
                   "feedforward included) instead of the planned angles")
    return p


def check_arguments(parser, args) -> None:
    check_walk_source(parser, args)


def run(args) -> int:
    out = Path(args.output)
    if out.suffix not in (".csv", ".npz"):
        raise UsageError(f"-o {out}: the output must end in .csv or .npz")
    output_path(out, "-o", args)
    walk = planned_walk(args)
    trajectory = walk.goals if getattr(args, "goals", False) else walk.planned
    terrain = getattr(args, "terrain", None)
    course = load_course(terrain).terrain if terrain is not None else None
    trajectory = replace(trajectory, origin=origin_for(walk.source.robot, terrain, course))  # it remembers its robot
    write_output(out, trajectory.save)
    walk.say_notes()
    print(f"wrote {out} for {walked_by(walk.source)}: {len(trajectory)} frames, {trajectory.t_s[-1]:.2f} s, "
          f"{len(walk.heel_strikes)} heel strikes, {trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.4f} m")
    refuse_what_walk_refuses(walk, out, getattr(args, "goals", False))
    return 0


def refuse_what_walk_refuses(walk, written, goals: bool = False) -> None:
    """``LimitBroken`` (exit 1, one line) if ``gaitbot walk`` would refuse the file ``written`` (``walk
    --trajectory``: the file as read back; a file of ``goals`` that differ from the planned angles: its
    joint limits only) or the walk itself (its goals; the body's planned motion for balance). A leg given on the command line has no robot, hence no limits."""
    config = walk.source.robot
    if config is None:
        return
    # A file of goals (--goals) overshoots the planned angles by the servos' sag: its balance is the planned
    # walk's (checked with the walk), so the file itself is checked against the joint limits only.
    goals = goals and walk.goals is not walk.planned
    reports = (preflight(config, load_fast(written), on_boom=goals),
               preflight(config, walk.goals, planned=walk.planned))
    for report in reports:
        if not report.ok:
            raise LimitBroken(f"wrote {written}, but gaitbot walk would refuse it: {report.first_error}"
                              f"{clearance_hint(walk.source)}")
