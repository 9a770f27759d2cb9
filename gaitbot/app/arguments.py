"""The option groups several commands share, each written once (every command module adds its own
sub-parser with these and its own options: ``add_parser(subparsers)``)."""

from __future__ import annotations

import argparse

from gaitbot.app.help import COMMAND_HELP, HelpFormatter
from gaitbot.app.steer_options import add_steer_options

#: What ``walk --dry-run`` and ``walk --sim`` walk when no steps are given: the demo (said on stderr).
DEMO_DISTANCE_M = 0.5

CALIBRATION_HELP = ("calibration file (gaitbot calibrate) applied on top of the robot config (default: "
                    "<config stem>.calibration.toml beside the config, if there is one)")
REPLY_TIMEOUT_HELP = "how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)"


def add_command(subparsers, name: str, **kwargs) -> argparse.ArgumentParser:
    """The sub-parser of command ``name`` ("walk", "eigen fit"), with its help texts (gaitbot.app.help)."""
    text = COMMAND_HELP[name]
    return subparsers.add_parser(name.split()[-1], help=text.summary, description=text.description,
                                 epilog=text.epilog, formatter_class=HelpFormatter, **kwargs)


def robot_options(p: argparse.ArgumentParser, robot_help: str) -> None:
    p.add_argument("--robot", help=robot_help)
    p.add_argument("--calibration", metavar="FILE", help=CALIBRATION_HELP)


def leg_options(p: argparse.ArgumentParser, what: str = "overrides the robot's leg") -> None:
    p.add_argument("--thigh", type=float, metavar="M", help=f"thigh length in metres ({what})")
    p.add_argument("--shank", type=float, metavar="M", help=f"shank length in metres ({what})")
    p.add_argument("--foot", type=float, metavar="M", help=f"foot length, heel to toe, in metres ({what})")


def walk_options(p: argparse.ArgumentParser, demo: bool = False) -> None:
    """What to walk (``--steps``, ``--distance``, ``--terrain``) and how (the robot, the leg, the timing):
    the options of plan, generate and walk (gaitbot.app.planned_walk reads them)."""
    what = p.add_mutually_exclusive_group(required=False)
    what.add_argument("--steps", metavar="A,B,...", help="step lengths in metres, comma separated, e.g. 0.05,0.08,0.08")
    what.add_argument("--distance", type=float, metavar="M",
                      help="distance to walk in metres, in the fewest equal steps"
                      + (f" (with --dry-run or --sim and no other source: {DEMO_DISTANCE_M:g}, the demo)"
                         if demo else ""))
    p.add_argument("--max-step", type=float, metavar="M",
                   help="longest step for --distance, metres (default: the robot's max_step_m)")
    p.add_argument("--perturb", type=float, default=0.0, metavar="SIGMA",
                   help="add zero-mean random noise of this standard deviation (metres) to step lengths")
    p.add_argument("--seed", type=int, help="random seed for --perturb (default: a different walk each time)")
    robot_options(p, "robot config: a .toml path or a shipped name (default xl430-biped)")
    leg_options(p)
    p.add_argument("--clearance", type=float, metavar="M",
                   help="how high the whole swing sole stays above the ground while the foot moves forward, "
                   "metres (default: the robot's clearance_m, which a balanced walk's speed fit may lower; "
                   "one given here is kept)")
    p.add_argument("--rate", type=float, metavar="HZ", help="frame rate in Hz (default: the robot's rate_hz)")
    p.add_argument("--cycle", type=float, metavar="S", help="walking cycle (two steps) in seconds "
                   "(default: the robot's cycle_s)")
    p.add_argument("--terrain", metavar="FILE", help="walk a terrain course (TOML, see config/terrain/) instead of "
                   "--steps/--distance")
    add_steer_options(p)  # --velocity/--duration, --commands (gaitbot.app.steer_options)


def bus_options(p: argparse.ArgumentParser, dry_run_help: str) -> None:
    p.add_argument("--port", help="serial port, e.g. /dev/ttyUSB0 (default: the robot config's; not with --dry-run)")
    p.add_argument("--dry-run", action="store_true", help=dry_run_help)
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP)


#: The options that each name a source of what to walk (one at most per command).
WALK_SOURCES = ("steps", "distance", "terrain", "trajectory", "velocity", "commands")


def check_walk_source(parser: argparse.ArgumentParser, args, demo: bool = False) -> None:
    """plan, generate and walk need exactly one source of steps; with ``demo`` (a walk on the mock bus or the
    simulated robot) none walks the demo, and says so."""
    sources = [name for name in WALK_SOURCES if getattr(args, name, None) is not None]
    if "velocity" in sources and "distance" in sources:  # --velocity VX,0,0 --distance M: one straight walk
        sources.remove("distance")
    if len(sources) > 1:
        parser.error(f"give one of --{' / --'.join(sources)}, not several")
    if sources:
        return
    if demo:
        args.distance = DEMO_DISTANCE_M
        args.demo = True  # said by the walk once its other options are found good (app/walk.py)
        return
    extra = " or --trajectory" if hasattr(args, "trajectory") else ""
    parser.error(f"give --steps, --distance or --terrain{extra} (e.g. --distance 1.0), or steer with --velocity "
                 "VX,VY,WZ --duration S or --commands FILE")
