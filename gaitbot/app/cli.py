"""The ``gaitbot`` command line: the parser, and each subcommand handed to its module in gaitbot.app.

Bad input (any ``gaitbot.errors.UserError``) prints one line and exits with status 2; a bus that
fails outside a walk session prints one line and exits with status 1 (a traceback only with --debug).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from gaitbot import __version__
from gaitbot.bus.base import BusError
from gaitbot.errors import UserError

#: Subcommand -> the module of gaitbot.app whose ``run(args)`` does it (imported when used: ``plot``
#: needs matplotlib, ``walk --sim`` MuJoCo, and the rest should not wait for them).
COMMANDS = {name: f"gaitbot.app.{name}" for name in ("plan", "generate", "plot", "walk", "check", "eigen", "record",
                                                     "scan")}


def _walk_inputs(p: argparse.ArgumentParser) -> None:
    what = p.add_mutually_exclusive_group(required=False)
    what.add_argument("--steps", help="step lengths in metres, comma separated, e.g. 0.05,0.08,0.08")
    what.add_argument("--distance", type=float, help="distance to walk in metres (fewest equal steps)")
    p.add_argument("--max-step", type=float, help="longest step for --distance, metres (default: the robot's max_step_m)")
    p.add_argument("--perturb", type=float, default=0.0, metavar="SIGMA",
                   help="add zero-mean random noise of this standard deviation (metres) to step lengths")
    p.add_argument("--seed", type=int, help="random seed for --perturb")
    p.add_argument("--robot", help="robot config (a .toml path or a shipped name; default xl430-biped)")
    p.add_argument("--thigh", type=float, help="thigh length in metres (overrides the robot's leg)")
    p.add_argument("--shank", type=float, help="shank length in metres")
    p.add_argument("--foot", type=float, help="foot length in metres")
    p.add_argument("--clearance", type=float, help="swing-foot clearance in metres (default: the robot's)")
    p.add_argument("--rate", type=float, help="frame rate in Hz (default: the robot's rate_hz)")
    p.add_argument("--cycle", type=float, metavar="SECONDS", help="walking cycle (two steps) in seconds "
                   "(default: the robot's cycle_s)")
    p.add_argument("--terrain", metavar="FILE", help="walk a terrain course (TOML, see config/terrain/) instead of "
                   "--steps/--distance")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="gaitbot", description="Walking gaits for small servo bipeds.")
    parser.add_argument("--version", action="version", version=f"gaitbot {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("plan", help="print the step plan")
    _walk_inputs(p)
    p.add_argument("--json", action="store_true", help="print the plan as one JSON object")

    p = sub.add_parser("generate", help="write the trajectory to CSV or NPZ")
    _walk_inputs(p)
    p.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")
    p.add_argument("--goals", action="store_true", help="write the goal angles a walk sends (servo-sag "
                   "feedforward included) instead of the planned angles")

    p = sub.add_parser("plot", help="draw a trajectory file to a PNG")
    p.add_argument("file", help="trajectory (.csv or .npz)")
    p.add_argument("-o", "--output", required=True, help="picture file, e.g. walk.png")
    p.add_argument("--robot", help="robot config whose leg drew the trajectory (default xl430-biped)")
    p.add_argument("--thigh", type=float)
    p.add_argument("--shank", type=float)
    p.add_argument("--foot", type=float)
    p.add_argument("--clearance", type=float)
    p.add_argument("--terrain", metavar="FILE", help="terrain course the trajectory walked: draw it")

    p = sub.add_parser("walk", help="walk the robot (or a dry run on the mock bus)")
    _walk_inputs(p)
    p.add_argument("--dry-run", action="store_true", help="use the mock bus: no hardware, exact packets")
    p.add_argument("--realtime", action="store_true", help="pace a dry run at the real frame rate")
    p.add_argument("--record", help="write every bus packet to this .jsonl file")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--reply-timeout-ms", type=float,
                   help="how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)")
    p.add_argument("--trajectory", metavar="FILE", help="walk a trajectory file (.csv/.npz: gaitbot generate, "
                   "eigen synth, record) instead of --steps/--distance; it streams at its own frame rate")
    p.add_argument("--sim", action="store_true",
                   help="walk the simulated robot (MuJoCo, the sim extra) and measure whether it really walks")
    p.add_argument("--boom", action="store_true", help="--sim: the torso rides a boom (slides forward and up, "
                   "pitch held) instead of floating free")
    p.add_argument("--free-pitch", action="store_true", help="--sim: the boom, with the torso free to pitch on it")
    p.add_argument("--push", type=float, metavar="N_S", help="--sim: push the torso sideways with this impulse "
                   "(N s, positive to the left) in the middle of a step half-way through the walk")
    p.add_argument("--video", metavar="FILE", help="--sim: render the walk to walk.gif or walk.mp4 (three-quarter view)")
    p.add_argument("--json", action="store_true", help="--sim: print the measurements as one JSON object")

    p = sub.add_parser("check", help="check a trajectory or a recorded run against the robot's limits")
    p.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    p.add_argument("--robot", help="robot config (default: a recording's own robot, else xl430-biped)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--margin-deg", type=float, default=0.0, help="warn within this many degrees of a limit")
    p.add_argument("--allow-partial", action="store_true",
                   help="recordings: ignore a truncated last line (with a warning), e.g. after a crash")

    p = sub.add_parser("eigen", help="eigen-gaits (seed 004): fit a model to example walks, synthesise walks")
    eigen = p.add_subparsers(dest="eigen_command", required=True)
    q = eigen.add_parser("fit", help="fit an eigen-gait model to example trajectory files")
    q.add_argument("examples", nargs="+", help="trajectory files (.npz or .csv), one walk each")
    q.add_argument("-o", "--output", required=True, help="model file, e.g. model.npz")
    q.add_argument("--robot", help="robot config whose leg walked the examples (default xl430-biped)")
    q.add_argument("--samples", type=int, default=100, help="samples per resampled cycle (default 100)")
    q.add_argument("--basis", choices=("fourier", "bspline"), default="fourier")
    q.add_argument("--n-basis", type=int, default=31, help="basis functions per channel (odd for fourier)")
    q.add_argument("--roughness", type=float, default=0.0, help="roughness penalty on the second derivative")
    q.add_argument("--pose-variance", type=float, default=0.95, help="share of pose variance the pose PCA keeps "
                   "at least (default 0.95)")
    q.add_argument("--pose-tolerance-deg", type=float, default=0.5, help="and more pose axes until no example pose "
                   "moves by more than this when projected (default 0.5; inf: the variance rule alone)")
    q.add_argument("--variance", type=float, default=0.95, help="share of variance the eigen-motions kept explain")
    q.add_argument("--components", type=int, help="keep exactly this many eigen-motions")
    q.add_argument("--align", choices=("dtw", "none"), default="dtw", help="time alignment of the cycles")
    q.add_argument("--label-degree", type=int, default=2, help="degree of the step-length regression")
    q = eigen.add_parser("synth", help="synthesise a walk from an eigen-gait model")
    q.add_argument("model", help="model file from `gaitbot eigen fit`")
    q.add_argument("--step-length", type=float, required=True, help="step length in metres")
    q.add_argument("--to-step-length", type=float, help="change the step length smoothly to this over the cycles")
    q.add_argument("--cycles", type=int, default=3, help="synthesised cycles (two steps each; default 3)")
    q.add_argument("--components", type=int, help="eigen-motions to use (default: those the model kept)")
    q.add_argument("--pose-deg", help="six joint angles in degrees the motion must pass through")
    q.add_argument("--pose-time", type=float, help="seconds into each synthesised cycle for --pose-deg")
    q.add_argument("--robot", help="robot config (default xl430-biped)")
    q.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")

    p = sub.add_parser("record", help="record a motion made by hand: torque off, positions read to a trajectory CSV")
    p.add_argument("--robot", help="robot config (a .toml path or a shipped name; default xl430-biped)")
    p.add_argument("-o", "--output", required=True, help="trajectory CSV, written as it is read, e.g. demo.csv")
    p.add_argument("--duration", type=float, help="seconds to record (default: until Ctrl-C)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--hold", action="store_true", help="at the end, hold the last pose (torque on) instead of "
                   "leaving torque off")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--dry-run", action="store_true", help="record from the mock bus (needs --duration)")
    p.add_argument("--reply-timeout-ms", type=float,
                   help="how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)")

    p = sub.add_parser("scan", help="list the servos that answer")
    p.add_argument("--robot", help="robot config (default xl430-biped)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--all", action="store_true", help="ping every id, not only the configured ones")
    p.add_argument("--dry-run", action="store_true", help="scan the mock bus")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    sources = [name for name in ("steps", "distance", "terrain", "trajectory") if getattr(args, name, None) is not None]
    if args.command in ("plan", "generate", "walk") and len(sources) > 1:
        parser.error(f"{args.command}: give one of --{' / --'.join(sources)}, not several")
    if args.command in ("plan", "generate", "walk") and not sources:
        if args.command == "walk" and (args.dry_run or args.sim):
            args.distance = 0.5  # the built-in demo: half a metre on the mock bus or the simulated robot
        else:
            parser.error(f"{args.command}: give --steps or --distance")
    try:
        return importlib.import_module(COMMANDS[args.command]).run(args)
    except UserError as exc:
        if args.debug:
            raise
        print(f"gaitbot {args.command}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return exc.exit_status
    except BusError as exc:  # a bus that fails outside a walk session (scan): one line, status 1
        if args.debug:
            raise
        print(f"gaitbot {args.command}: bus error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
