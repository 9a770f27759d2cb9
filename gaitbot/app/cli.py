"""The ``gaitbot`` command line: the parser, and each subcommand handed to its module in gaitbot.app.

Bad input (any ``gaitbot.errors.UserError``) prints one line and exits with status 2; a bus that
fails outside a walk session prints one line and exits with status 1 (a traceback only with --debug).
"""

from __future__ import annotations

import os
import signal
import sys
import textwrap
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
from gaitbot.errors import UserError  # noqa: E402
from gaitbot.stream.signals import StopSignals, Terminated  # noqa: E402 - light: rooms come with the commands

#: Subcommand -> the module of gaitbot.app whose ``run(args)`` does it (imported when used: ``plot``
#: needs matplotlib, ``walk --sim`` MuJoCo, and the rest should not wait for them).
COMMANDS = {name: f"gaitbot.app.{name}" for name in ("plan", "generate", "plot", "walk", "check", "eigen", "record",
                                                     "scan", "setup", "calibrate")}

CALIBRATION_HELP = ("calibration file (gaitbot calibrate) applied on top of the robot config (default: "
                    "<config stem>.calibration.toml beside the config, if there is one)")
REPLY_TIMEOUT_HELP = "how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)"


def _calibration(p: argparse.ArgumentParser) -> None:
    p.add_argument("--calibration", metavar="FILE", help=CALIBRATION_HELP)


def _described(sub, name: str, help: str, description: str, examples: str) -> argparse.ArgumentParser:
    """A subcommand with a description and examples in its --help."""
    return sub.add_parser(name, help=help, description=textwrap.fill(description, 100),
                          epilog="examples:\n" + examples, formatter_class=argparse.RawDescriptionHelpFormatter)


def _walk_inputs(p: argparse.ArgumentParser) -> None:
    what = p.add_mutually_exclusive_group(required=False)
    what.add_argument("--steps", help="step lengths in metres, comma separated, e.g. 0.05,0.08,0.08")
    what.add_argument("--distance", type=float, help="distance to walk in metres (fewest equal steps)")
    p.add_argument("--max-step", type=float, help="longest step for --distance, metres (default: the robot's max_step_m)")
    p.add_argument("--perturb", type=float, default=0.0, metavar="SIGMA",
                   help="add zero-mean random noise of this standard deviation (metres) to step lengths")
    p.add_argument("--seed", type=int, help="random seed for --perturb")
    p.add_argument("--robot", help="robot config (a .toml path or a shipped name; default xl430-biped)")
    _calibration(p)
    p.add_argument("--thigh", type=float, help="thigh length in metres (overrides the robot's leg)")
    p.add_argument("--shank", type=float, help="shank length in metres")
    p.add_argument("--foot", type=float, help="foot length in metres")
    p.add_argument("--clearance", type=float, help="swing-foot clearance in metres (default: the robot's)")
    p.add_argument("--rate", type=float, help="frame rate in Hz (default: the robot's rate_hz)")
    p.add_argument("--terrain", metavar="FILE", help="walk a terrain course (TOML, see config/terrain/) instead of "
                   "--steps/--distance")


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the program, the error, where to look) and exit 2: no usage
    block around it (``--help`` still prints the usage)."""

    def error(self, message: str):  # noqa: D401 - argparse's name
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="gaitbot", description="Walking gaits for small servo bipeds.")
    parser.add_argument("--version", action="version", version=f"gaitbot {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("plan", help="print the step plan")
    _walk_inputs(p)
    p.add_argument("--json", action="store_true", help="print the plan as one JSON object")

    p = sub.add_parser("generate", help="write the trajectory to CSV or NPZ")
    _walk_inputs(p)
    p.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")

    p = sub.add_parser("plot", help="draw a trajectory file to a PNG")
    p.add_argument("file", help="trajectory (.csv or .npz)")
    p.add_argument("-o", "--output", required=True, help="picture file, e.g. walk.png")
    p.add_argument("--robot", help="robot config whose leg drew the trajectory (default xl430-biped)")
    _calibration(p)
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
    p.add_argument("--free-pitch", action="store_true", help="--sim: let the torso pitch freely (default: held by a boom)")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: accept a walk that would tip a free-standing robot")
    p.add_argument("--video", metavar="FILE", help="--sim: render the walk to walk.gif or walk.mp4 (side view)")
    p.add_argument("--json", action="store_true", help="--sim: print the measurements as one JSON object")

    p = sub.add_parser("check", help="check a trajectory or a recorded run against the robot's limits")
    p.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    p.add_argument("--robot", help="robot config (default: a recording's own robot, else xl430-biped)")
    _calibration(p)
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--margin-deg", type=float, default=0.0, help="warn within this many degrees of a limit")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: do not check its balance (ZMP against the support polygon)")
    p.add_argument("--allow-partial", action="store_true",
                   help="recordings: ignore a truncated last line (with a warning), e.g. after a crash")

    p = sub.add_parser("eigen", help="eigen-gaits (seed 004): fit a model to example walks, synthesise walks")
    eigen = p.add_subparsers(dest="eigen_command", required=True)
    q = eigen.add_parser("fit", help="fit an eigen-gait model to example trajectory files")
    q.add_argument("examples", nargs="+", help="trajectory files (.npz or .csv), one walk each")
    q.add_argument("-o", "--output", required=True, help="model file, e.g. model.npz")
    q.add_argument("--robot", help="robot config whose leg walked the examples (default xl430-biped)")
    _calibration(q)
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
    _calibration(q)
    q.add_argument("-o", "--output", required=True, help="walk.csv or walk.npz")

    p = sub.add_parser("record", help="record a motion made by hand: torque off, positions read to a trajectory CSV")
    p.add_argument("--robot", help="robot config (a .toml path or a shipped name; default xl430-biped)")
    _calibration(p)
    p.add_argument("-o", "--output", required=True, help="trajectory CSV, written as it is read, e.g. demo.csv")
    p.add_argument("--duration", type=float, help="seconds to record (default: until Ctrl-C)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--hold", action="store_true", help="at the end, hold the last pose (torque on) instead of "
                   "leaving torque off")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--dry-run", action="store_true", help="record from the mock bus (needs --duration)")
    p.add_argument("--reply-timeout-ms", type=float,
                   help="how long to wait for each status packet (default: the SDK's, about 34 ms at 1 Mbaud)")

    p = _described(
        sub, "scan", "list every servo that answers, at every baud rate",
        "Ping every id at every baud rate of the configured protocol (or --baud) and list each servo that answers: "
        "id, baud rate, model, firmware, present position (ticks and as its joint's angle), input voltage, "
        "temperature, load, torque and hardware errors in words; then the configured joints that did not answer. "
        "Reads only. Exit 0 when every configured joint answered as configured, else 1.",
        "  gaitbot scan --robot config/xl430-biped.toml --port /dev/ttyUSB0\n"
        "  gaitbot scan --robot ax12a-biped --baud 1000000 --json\n"
        "  gaitbot scan --dry-run")
    p.add_argument("--robot", help="robot config: its protocol, and the joints to match (default xl430-biped)")
    _calibration(p)
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--baud", type=int, help="scan this baud rate only (default: every rate a servo of the "
                   "configured protocol can run at)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--reply-timeout-ms", type=float, help=REPLY_TIMEOUT_HELP + "; a short one (5) speeds up "
                   "Protocol 1.0, which pings 254 ids one by one at each rate")
    p.add_argument("--dry-run", action="store_true", help="scan the mock bus (the config's servos at its baud rate)")

    p = _described(
        sub, "setup", "give new servos, one at a time, the config's ids and baud rate",
        "For each joint (or each --joint), asks you to connect only that joint's servo, finds it at any id and any "
        "baud rate its model can run at, and writes the joint's id and the config's baud rate (torque off, the "
        "Feetech EEPROM lock, ID, Baud Rate: nothing else), then reads them back. Refuses (exit 2, nothing "
        "written) when more than one servo answers or the servo is not the config's model.",
        "  gaitbot setup --robot config/xl430-biped.toml --port /dev/ttyUSB0\n"
        "  gaitbot setup --robot ax12a-biped --joint knee_pitch_left --yes --reply-timeout-ms 5")
    p.add_argument("--robot", help="robot config: the ids, models and baud rate to give (default xl430-biped)")
    _calibration(p)
    p.add_argument("--joint", action="append", metavar="NAME", help="set up this joint only (repeat for several; "
                   "default: every joint, in the config's order)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="do not wait for Enter: the servo is already connected")
    p.add_argument("--reply-timeout-ms", type=float, help=REPLY_TIMEOUT_HELP + "; a short one (5) speeds up the "
                   "search, which tries every id at every baud rate")

    p = _described(
        sub, "calibrate", "measure each joint's zero tick and direction into a calibration file",
        "Torque off; you hold the robot in its zero pose (legs straight, feet flat) and press Enter: the present "
        "positions become the zero ticks. Then, joint by joint, you bend the joint in its positive direction "
        "(told in words) and press Enter: the sign of the change is its direction, the size is checked against "
        "the configured limits. Writes the calibration file, which every command applies on top of the config "
        "(--calibration FILE, or <config stem>.calibration.toml beside the config). Writes only Torque Enable = 0 "
        "to the servos.",
        "  gaitbot calibrate --robot robots/mybot.toml -o robots/mybot.calibration.toml\n"
        "  gaitbot walk --robot robots/mybot.toml --calibration mybot.calibration.toml --distance 0.5")
    p.add_argument("--robot", help="robot config (default xl430-biped)")
    p.add_argument("-o", "--output", required=True, help="calibration file to write (.toml)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--reply-timeout-ms", type=float, help=REPLY_TIMEOUT_HELP)
    return parser


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
    sources = [name for name in ("steps", "distance", "terrain", "trajectory") if getattr(args, name, None) is not None]
    if args.command in ("plan", "generate", "walk") and len(sources) > 1:
        parser.error(f"{args.command}: give one of --{' / --'.join(sources)}, not several")
    if args.command in ("plan", "generate", "walk") and not sources:
        if args.command == "walk" and (args.dry_run or args.sim):
            args.distance = 0.5  # the built-in demo: half a metre on the mock bus or the simulated robot
        else:
            parser.error(f"{args.command}: give --steps or --distance")
    if not args.debug:  # an error is one line: no RuntimeWarning or library warning around it (--debug shows them)
        warnings.simplefilter("ignore")
    from gaitbot.bus.base import BusError  # imported here: the bus room brings the vendor SDKs and numpy

    try:
        return importlib.import_module(COMMANDS[args.command]).run(args)
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
    except BrokenPipeError:  # the reader of our output went away (``| head``): nothing more to say to anyone
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except OSError:
            pass
        return 1
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
