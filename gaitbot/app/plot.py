"""``gaitbot plot``: a trajectory (or an eigen-gait model) drawn to a picture (gaitbot.plot)."""

from __future__ import annotations

from pathlib import Path

from gaitbot.app.arguments import add_command, leg_options, robot_options
from gaitbot.app.file_robot import robot_for_file, terrain_for_file
from gaitbot.app.options import UsageError, file_option, gait_source, walked_by
from gaitbot.app.outputs import output_path, write_output
from gaitbot.errors import UserError
from gaitbot.gait.eigen import is_model_file
from gaitbot.gait.trajectory import Trajectory


def add_parser(subparsers):
    p = add_command(subparsers, "plot")
    p.add_argument("file", help="trajectory (.csv or .npz), or an eigen-gait model (.npz from gaitbot eigen fit)")
    p.add_argument("-o", "--output", required=True, help="picture file, e.g. walk.png (or .svg, .pdf)")
    robot_options(p, "robot config whose leg walked the trajectory (default: the robot the file was made for, "
                  "else xl430-biped)")
    p.add_argument("--commands", metavar="FILE", help="a steered walk's commands (JSON Lines), drawn over time")
    leg_options(p, "if the trajectory was made with another leg")
    p.add_argument("--clearance", type=float, metavar="M",
                   help="clearance line drawn on the foot heights, metres (default: the robot's clearance_m)")
    p.add_argument("--terrain", metavar="FILE", help="terrain course the trajectory walked: draw it, and foot heights "
                   "above it (default: the course the file was made on)")
    return p


def run(args) -> int:
    try:
        import matplotlib  # noqa: F401  (only plotting needs it: the `plot` extra)
    except ImportError:
        raise UsageError("plotting needs matplotlib: pip install 'gaitbot[plot]'") from None
    from gaitbot.plot import plot_eigen_model, plot_trajectory

    out = output_path(args.output, "-o", args)
    from matplotlib.backend_bases import FigureCanvasBase

    formats = sorted(FigureCanvasBase.get_supported_filetypes())
    if out.suffix.lower().lstrip(".") not in formats:
        raise UsageError(f"-o {out}: the picture's name must end in a format matplotlib writes "
                         f"({', '.join('.' + f for f in formats)})")
    if Path(args.file).suffix == ".npz" and is_model_file(args.file):
        try:
            write_output(out, lambda path: plot_eigen_model(args.file, path))
        except (ValueError, ArithmeticError) as exc:
            if isinstance(exc, UserError):
                raise
            raise UsageError(f"{args.file}: this model cannot be drawn ({' '.join(str(exc).split())})") from None
        print(f"wrote {args.output}")
        return 0
    trajectory = Trajectory.load(args.file)
    robot = robot_for_file(args.file, trajectory.origin, args.robot, getattr(args, "calibration", None))
    terrain = terrain_for_file(args.file, trajectory.origin, getattr(args, "terrain", None))
    source = gait_source(args, robot)
    if source.robot is not None and source.robot.is_3d and terrain is None:
        from gaitbot.plot.balance import plot_balance

        commands = None
        if getattr(args, "commands", None) is not None:
            from gaitbot.gait.steer.command import read_commands

            commands = read_commands(file_option(args.commands, "--commands"))
        write_output(out, lambda path: plot_balance(trajectory, source.robot, path, title=Path(args.file).name,
                                                    commands=commands))
        print(f"wrote {out} (drawn for {source.robot.name})")
        return 0
    write_output(out, lambda path: plot_trajectory(trajectory, source.geometry, path, clearance=source.settings.clearance,
                                                   title=Path(args.file).name, terrain=terrain))
    ground = "" if terrain is None else \
        f", on a course of {len(terrain.treads)} tread{'' if len(terrain.treads) == 1 else 's'}"
    print(f"wrote {out} (the feet drawn for {walked_by(source)}{ground})")
    return 0
