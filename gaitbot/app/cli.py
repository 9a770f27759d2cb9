"""The ``gaitbot`` command line: the parser, and each subcommand handed to its module in gaitbot.app.

Exit statuses are part of the interface (docs/command-line.md): 0 success; 1 the robot or the check
failed (a limit broken, a bus fault, a fall in the simulation); 2 bad input (any
``gaitbot.errors.UserError`` or usage error: one line, nothing sent to a servo); 130 Ctrl-C and 143
SIGTERM during a walk or a recording; 141 when whoever reads the output stops reading (``| head``).
A traceback only with --debug.
"""

from __future__ import annotations

import os
import signal
import sys
import threading

#: Signals that came while the command line was still being imported (the command then ends at once,
#: exit 130 or 143, nothing sent). Caught only when this module is the program being run, never when a
#: script or a test imports it.
EARLY_SIGNALS: list[int] = []
#: True when this module is the program being run (the console script, ``python -m gaitbot``).
RUN_AS_PROGRAM = os.path.basename(sys.argv[0] if sys.argv else "") in ("gaitbot", "cli.py", "__main__.py") \
    and threading.current_thread() is threading.main_thread()
if RUN_AS_PROGRAM:
    for _signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(_signum, lambda signum, _frame: EARLY_SIGNALS.append(signum))

import argparse  # noqa: E402 - after the early handlers: imports take a tenth of a second
import importlib  # noqa: E402
import warnings  # noqa: E402

from gaitbot import __version__  # noqa: E402
from gaitbot.app.help import COMMAND_HELP, DESCRIPTION, EPILOG, HelpFormatter  # noqa: E402
from gaitbot.app.steer_options import add_steer_options, steer_sources  # noqa: E402
from gaitbot.errors import UserError  # noqa: E402
from gaitbot.stream.signals import StopSignals, Terminated  # noqa: E402 - light: rooms come with the commands

#: Subcommand -> the module of gaitbot.app whose ``run(args)`` does it (imported when used: ``plot``
#: needs matplotlib, ``walk --sim`` MuJoCo, and the rest should not wait for them).
COMMANDS = {name: f"gaitbot.app.{name}" for name in ("plan", "generate", "plot", "walk", "check", "eigen", "record",
                                                     "scan", "setup", "calibrate", "drive")}

#: What ``walk --dry-run`` and ``walk --sim`` walk when no steps are given: the demo (said on stderr).
DEMO_DISTANCE_M = 0.5

#: Exit status when the reader of our output went away (like a program killed by SIGPIPE: 128 + 13).
EXIT_BROKEN_PIPE = 141

CALIBRATION_HELP = ("calibration file (gaitbot calibrate) applied on top of the robot config (default: "
                    "<config stem>.calibration.toml beside the config, if there is one)")
REPLY_TIMEOUT_HELP = "how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)"


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the program, the error, where to look) and exit 2: no usage
    block around it (``--help`` still prints the usage). Subcommands' parsers are of the same class."""

    def error(self, message: str):  # noqa: D401 - argparse's name
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)\n")


def _robot_options(p: argparse.ArgumentParser, robot_help: str) -> None:
    p.add_argument("--robot", help=robot_help)
    p.add_argument("--calibration", metavar="FILE", help=CALIBRATION_HELP)


def _leg_options(p: argparse.ArgumentParser, what: str = "overrides the robot's leg") -> None:
    p.add_argument("--thigh", type=float, metavar="M", help=f"thigh length in metres ({what})")
    p.add_argument("--shank", type=float, metavar="M", help=f"shank length in metres ({what})")
    p.add_argument("--foot", type=float, metavar="M", help=f"foot length, heel to toe, in metres ({what})")


def _walk_inputs(p: argparse.ArgumentParser, demo: bool = False) -> None:
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
    _robot_options(p, "robot config: a .toml path or a shipped name (default xl430-biped)")
    _leg_options(p)
    p.add_argument("--clearance", type=float, metavar="M",
                   help="how high the whole swing sole stays above the ground while the foot moves forward, "
                   "metres (default: the robot's clearance_m)")
    p.add_argument("--rate", type=float, metavar="HZ", help="frame rate in Hz (default: the robot's rate_hz)")
    p.add_argument("--cycle", type=float, metavar="S", help="walking cycle (two steps) in seconds "
                   "(default: the robot's cycle_s)")
    p.add_argument("--terrain", metavar="FILE", help="walk a terrain course (TOML, see config/terrain/) instead of "
                   "--steps/--distance")
    add_steer_options(p)  # --velocity/--duration, --commands (gaitbot.app.steer_options)


def _bus_options(p: argparse.ArgumentParser, dry_run_help: str) -> None:
    p.add_argument("--port", help="serial port, e.g. /dev/ttyUSB0 (default: the robot config's; not with --dry-run)")
    p.add_argument("--dry-run", action="store_true", help=dry_run_help)
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP)


def _command(sub, name: str, **kwargs) -> argparse.ArgumentParser:
    text = COMMAND_HELP[name]
    return sub.add_parser(name.split()[-1], help=text.summary, description=text.description, epilog=text.epilog,
                          formatter_class=HelpFormatter, **kwargs)


def build_parser() -> argparse.ArgumentParser:
    """The parser; ``parser.commands`` maps each subcommand to its own parser (its errors print its usage)."""
    parser = OneLineParser(prog="gaitbot", description=DESCRIPTION, epilog=EPILOG, formatter_class=HelpFormatter)
    parser.add_argument("--version", action="version", version=f"gaitbot {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    parser.commands = {}

    p = parser.commands["plan"] = _command(sub, "plan")
    _walk_inputs(p)
    p.add_argument("--json", action="store_true", help="print the plan as one JSON object")

    p = parser.commands["generate"] = _command(sub, "generate")
    _walk_inputs(p)
    p.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz (file formats: docs/file-formats.md)")
    p.add_argument("--goals", action="store_true", help="write the goal angles a walk sends (servo-sag "
                   "feedforward included) instead of the planned angles")

    p = parser.commands["plot"] = _command(sub, "plot")
    p.add_argument("file", help="trajectory (.csv or .npz), or an eigen-gait model (.npz from gaitbot eigen fit)")
    p.add_argument("-o", "--output", required=True, help="picture file, e.g. walk.png (or .svg, .pdf)")
    _robot_options(p, "robot config whose leg walked the trajectory (default xl430-biped)")
    _leg_options(p, "if the trajectory was made with another leg")
    p.add_argument("--clearance", type=float, metavar="M",
                   help="clearance line drawn on the foot heights, metres (default: the robot's clearance_m)")
    p.add_argument("--terrain", metavar="FILE", help="terrain course the trajectory walked: draw it, and foot heights "
                   "above it")

    p = parser.commands["walk"] = _command(sub, "walk")
    _walk_inputs(p, demo=True)
    p.add_argument("--trajectory", metavar="FILE", help="walk a trajectory file (.csv/.npz: gaitbot generate, "
                   "eigen synth, record) instead of --steps/--distance; it streams at its own frame rate")
    _bus_options(p, "use the mock bus under the real SDK: no hardware, and every packet exactly as a real walk sends it")
    p.add_argument("--realtime", action="store_true",
                   help="--dry-run: pace it at the real frame rate (default: a simulated clock, as fast as it goes)")
    p.add_argument("--record", metavar="FILE", help="write every bus packet to this .jsonl file (gaitbot check reads it)")
    p.add_argument("--sim", action="store_true",
                   help="walk the simulated robot (MuJoCo) and measure whether it really walks")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: accept a walk that would tip a free-standing robot (with --sim: "
                   "the simulated torso rides a boom, sliding forward and up, pitch held)")
    p.add_argument("--free-pitch", action="store_true", help="--sim: the boom, with the torso free to pitch on it")
    p.add_argument("--push", type=float, metavar="N_S", help="--sim: push the torso sideways with this impulse "
                   "(N s, positive to the left) in the middle of a step half-way through the walk")
    p.add_argument("--video", metavar="FILE", help="--sim: render the walk to walk.gif or walk.mp4 (three-quarter view)")
    p.add_argument("--json", action="store_true", help="--sim: print the measurements as one JSON object")

    parser.commands["drive"] = importlib.import_module("gaitbot.app.drive").add_parser(sub, COMMAND_HELP)

    p = parser.commands["check"] = _command(sub, "check")
    p.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    _robot_options(p, "robot config (default: a recording's own robot, else xl430-biped)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--margin-deg", type=float, default=0.0, metavar="DEG",
                   help="warn within this many degrees of a limit (default 0)")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: do not check its balance (ZMP against the support polygon)")
    p.add_argument("--allow-partial", action="store_true",
                   help="recordings: ignore a truncated last line (with a warning), e.g. after a crash")

    p = parser.commands["eigen"] = _command(sub, "eigen")
    eigen = p.add_subparsers(dest="eigen_command", required=True, metavar="{fit,synth}")
    q = parser.commands["eigen fit"] = _command(eigen, "eigen fit")
    q.add_argument("examples", nargs="+", help="trajectory files (.npz or .csv), one walk each")
    q.add_argument("-o", "--output", required=True, help="model file, e.g. model.npz")
    _robot_options(q, "robot config whose leg walked the examples (default xl430-biped); the model remembers it")
    _leg_options(q, "when the examples were walked with another leg than the robot's; the model remembers it")
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
    q = parser.commands["eigen synth"] = _command(eigen, "eigen synth")
    q.add_argument("model", help="model file from gaitbot eigen fit")
    q.add_argument("--step-length", type=float, required=True, metavar="M", help="step length in metres")
    q.add_argument("--to-step-length", type=float, metavar="M",
                   help="change the step length smoothly to this over the cycles")
    q.add_argument("--cycles", type=int, default=3, help="synthesised cycles (two steps each; default 3)")
    q.add_argument("--components", type=int, metavar="N", help="eigen-motions to use (default: those the model kept)")
    q.add_argument("--pose-deg", metavar="DEG,DEG,...",
                   help="the pose the motion must pass through: one angle in degrees per joint of the model, in its "
                   "order (eigen fit prints it; six pitch joints: hip, knee, ankle left, then right); write "
                   "--pose-deg=-5,... when the first is negative")
    q.add_argument("--pose-time", type=float, metavar="S", help="seconds into each synthesised cycle for --pose-deg")
    _robot_options(q, "robot config (default: the robot the model was fitted for)")
    _leg_options(q, "must be the leg the model was fitted with")
    q.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")

    p = parser.commands["record"] = _command(sub, "record")
    _robot_options(p, "robot config: a .toml path or a shipped name (default xl430-biped)")
    p.add_argument("-o", "--output", required=True, help="trajectory CSV, written as it is read, e.g. demo.csv")
    p.add_argument("--duration", type=float, metavar="S", help="seconds to record (default: until Ctrl-C)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--hold", action="store_true", help="at the end, hold the last pose (torque on) instead of "
                   "leaving torque off")
    _bus_options(p, "record from the mock bus (needs --duration)")

    p = parser.commands["scan"] = _command(sub, "scan")
    _robot_options(p, "robot config: its protocol, and the joints to match (default xl430-biped)")
    p.add_argument("--baud", type=int, help="scan this baud rate only (default: every rate a servo of the "
                   "configured protocol can run at)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    _bus_options(p, "scan the mock bus (the config's servos at its baud rate)")

    p = parser.commands["setup"] = _command(sub, "setup")
    _robot_options(p, "robot config: the ids, models and baud rate to give (default xl430-biped)")
    p.add_argument("--joint", action="append", metavar="NAME", help="set up this joint only (repeat for several; "
                   "default: every joint, in the config's order)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="do not wait for Enter: the servo is already connected")
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP + "; a short one (5) "
                   "speeds up the search, which tries every id at every baud rate")

    p = parser.commands["calibrate"] = _command(sub, "calibrate")
    p.add_argument("--robot", help="robot config (default xl430-biped)")
    p.add_argument("-o", "--output", required=True, help="calibration file to write (.toml)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP)
    return parser


def check_sources(parser: argparse.ArgumentParser, args) -> None:
    """plan, generate and walk need exactly one source of steps; a walk on the mock bus or the simulated robot
    without one walks the demo, and says so."""
    if args.command not in ("plan", "generate", "walk"):
        return
    own = parser.commands[args.command]
    sources = [name for name in ("steps", "distance", "terrain", "trajectory") if getattr(args, name, None) is not None]
    sources += steer_sources(args)
    if "velocity" in sources and "distance" in sources:  # --velocity VX,0,0 --distance M: one straight walk
        sources.remove("distance")
    if len(sources) > 1:
        own.error(f"give one of --{' / --'.join(sources)}, not several")
    if sources:
        return
    if args.command == "walk" and (args.dry_run or args.sim):
        args.distance = DEMO_DISTANCE_M
        args.demo = True  # said by the walk once its other options are found good (app/walk.py)
        return
    extra = " or --trajectory" if args.command == "walk" else ""
    own.error(f"give --steps, --distance, --velocity, --commands or --terrain{extra} (e.g. --distance 1.0)")


def _closed_output() -> int:
    """Our reader went away (``gaitbot check --json x | head -1``): stop quietly. Further writes to stdout
    (at exit, its flush) go to /dev/null instead of raising again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return EXIT_BROKEN_PIPE


def main(argv: list[str] | None = None) -> int:
    signals = StopSignals()  # first: a Ctrl-C from here on is one line and exit 130, never a traceback
    signals.install()
    if EARLY_SIGNALS:
        signals.received, signals.first_signal = len(EARLY_SIGNALS), EARLY_SIGNALS[0]
        signals.ignore_from_now()
        terminated = EARLY_SIGNALS[0] == signal.SIGTERM
        print(f"gaitbot: {'terminated (SIGTERM)' if terminated else 'interrupted (Ctrl-C)'} while starting; "
              "nothing was sent", file=sys.stderr)
        return 143 if terminated else 130
    try:
        return _main(argv, signals)
    except (KeyboardInterrupt, Terminated):  # while parsing or importing, before a command ran
        terminated = signals.first_signal == signal.SIGTERM
        print(f"gaitbot: {'terminated (SIGTERM)' if terminated else 'interrupted (Ctrl-C)'}; nothing was sent",
              file=sys.stderr)
        return 143 if terminated else 130
    finally:
        if signals.received or RUN_AS_PROGRAM:  # the process is ending: a late signal must not become a traceback
            signals.ignore_from_now()
        else:
            signals.restore()


def _main(argv: list[str] | None, signals: StopSignals) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    check_sources(parser, args)
    if not args.debug:  # an error is one line: no RuntimeWarning or library warning around it (--debug shows them)
        warnings.simplefilter("ignore")
    from gaitbot.bus.base import BusError  # imported here: the bus room brings the vendor SDKs and numpy

    try:
        return importlib.import_module(COMMANDS[args.command]).run(args)
    except BrokenPipeError:
        return _closed_output()
    except (KeyboardInterrupt, Terminated):  # before or after a session (a session handles its own)
        if args.debug:
            raise
        terminated = signals.first_signal == signal.SIGTERM
        print(f"gaitbot {args.command}: {'terminated (SIGTERM)' if terminated else 'interrupted (Ctrl-C)'}; "
              "nothing more was sent", file=sys.stderr)
        return 143 if terminated else 130
    except UserError as exc:
        if args.debug:
            raise
        print(f"gaitbot {args.command}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return exc.exit_status
    except OSError as exc:  # a file named on the command line that the OS refuses (a name too long, a loop ...)
        if args.debug:
            raise
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"gaitbot {args.command}: error: {' '.join((where + (exc.strerror or str(exc))).split())}",
              file=sys.stderr)
        return 2
    except BusError as exc:  # a bus that fails outside a walk session (scan): one line, status 1
        if args.debug:
            raise
        print(f"gaitbot {args.command}: bus error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
