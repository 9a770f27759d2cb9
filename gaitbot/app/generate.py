"""``gaitbot generate``: the trajectory of a walk, written as CSV or NPZ (docs/file-formats.md).

``--goals`` writes the goal angles a walk sends instead of the planned ones: for a balanced robot with
servo-sag feedforward, each planned angle plus its gravity torque over the servo's stiffness (exactly
what a dry-run recording of the same walk decodes to); for others the planned angles themselves.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from gaitbot.app.arguments import add_command, check_walk_source, walk_options
from gaitbot.app.options import UsageError, walked_by
from gaitbot.app.outputs import output_path, write_output
from gaitbot.app.planned_walk import planned_walk
from gaitbot.gait.terrain.course_file import load_course
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
    print(f"wrote {out} for {walked_by(walk.source)}: {len(trajectory)} frames, {trajectory.t_s[-1]:.2f} s, "
          f"{len(walk.heel_strikes)} heel strikes, {trajectory.root_m[-1, 0] - trajectory.root_m[0, 0]:.4f} m")
    return 0
