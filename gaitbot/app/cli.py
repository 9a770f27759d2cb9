"""The ``gaitbot`` command line: the parser, and each subcommand handed to its module in gaitbot.app.

Exit statuses are part of the interface (docs/command-line.md): 0 success; 1 the robot or the check
failed (a limit broken, a bus fault, a fall in the simulation); 2 bad input (any
``gaitbot.errors.UserError`` or usage error: one line, nothing sent to a servo); 130 Ctrl-C and 143
SIGTERM during a walk or a recording; 141 when whoever reads the output stops reading (``| head``).
A traceback only with --debug.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import signal
import sys
import warnings
from collections.abc import Sequence

from gaitbot import __version__
from gaitbot.app.arguments import add_command
from gaitbot.app.help import DESCRIPTION, EPILOG, HelpFormatter
from gaitbot.errors import UserError
from gaitbot.stream.signals import StopSignals, Terminated, signals_held  # light: rooms come with the commands

#: Subcommand -> the module of gaitbot.app that adds its sub-parser (``add_parser(subparsers)``) and does it
#: (``run(args)``). Only the module of the command given is imported (``plot`` needs matplotlib, ``walk
#: --sim`` MuJoCo, and the rest should not wait for them); the others appear in ``--help`` by their summary.
COMMANDS = {name: f"gaitbot.app.{name}" for name in ("plan", "generate", "plot", "walk", "check", "eigen", "record",
                                                     "scan", "setup", "calibrate", "robot", "drive")}

#: Exit status when the reader of our output went away (like a program killed by SIGPIPE: 128 + 13).
EXIT_BROKEN_PIPE = 141


#: A value that is a number or a comma-separated list of numbers, negative ones included (``-0.05,-0.05``,
#: ``-0.1,0,15``, ``-1e-3``): argparse takes only a lone negative number for a value, and anything else
#: starting with "-" for an option ("expected one argument"). No gaitbot option looks like a number.
NUMBERS = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)*$")


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the program, the error, where to look) and exit 2: no usage
    block around it (``--help`` still prints the usage); a list of numbers that starts with a negative one is
    a value (NUMBERS). Subcommands' parsers are of the same class."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NUMBERS  # argparse's own hook (tests/app: negative step lists)

    def error(self, message: str):  # noqa: D401 - argparse's name
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)\n")


def build_parser(commands: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The parser, with the options of ``commands`` (default: every command; the others are listed by their
    summary only). ``parser.commands`` maps each subcommand with its options to its own parser (its errors
    print its usage)."""
    parser = OneLineParser(prog="gaitbot", description=DESCRIPTION, epilog=EPILOG, formatter_class=HelpFormatter)
    parser.add_argument("--version", action="version", version=f"gaitbot {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    parser.commands = {}
    for name, module in COMMANDS.items():
        if commands is not None and name not in commands:
            add_command(sub, name)
            continue
        own = importlib.import_module(module).add_parser(sub)
        parser.commands[name] = own
        parser.commands.update(getattr(own, "commands", {}))
    return parser


def command_named(argv: Sequence[str]) -> str | None:
    """The subcommand of an argument list (the first argument that is not an option: the program's own
    options take no value), if it is one."""
    first = next((a for a in argv if not a.startswith("-")), None)
    return first if first in COMMANDS else None


def _closed_output() -> int:
    """Our reader went away (``gaitbot check --json x | head -1``): stop quietly. Further writes to stdout
    (at exit, its flush) go to /dev/null instead of raising again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return EXIT_BROKEN_PIPE


def main(argv: Sequence[str] | None = None, *, early_signals: Sequence[int] = (), as_program: bool = False) -> int:
    """Run one command. The signal policy (gaitbot.stream.signals.StopSignals) is installed first, so a
    Ctrl-C from here on is one line and exit 130, never a traceback. ``early_signals``: signals the program's
    entry point (gaitbot.app.entry) caught while it imported this module: the command then ends at once,
    nothing sent. ``as_program``: the process ends after this call (further signals are then ignored; else
    the old handlers come back)."""
    signals = StopSignals()
    signals.install()
    if early_signals:
        signals.received, signals.first_signal = len(early_signals), early_signals[0]
        signals.ignore_from_now()
        print(f"gaitbot: {_signal_words(early_signals[0])} while starting; nothing was sent", file=sys.stderr)
        return _signal_status(early_signals[0])
    try:
        return _main(argv, signals)
    except (KeyboardInterrupt, Terminated):  # while parsing or importing, before a command ran
        print(f"gaitbot: {_signal_words(signals.first_signal)}; nothing was sent", file=sys.stderr)
        return _signal_status(signals.first_signal)
    finally:
        if signals.received or as_program:  # the process is ending: a late signal must not become a traceback
            signals.ignore_from_now()
        else:
            signals.restore()


def _signal_words(signum: int | None) -> str:
    return "terminated (SIGTERM)" if signum == signal.SIGTERM else "interrupted (Ctrl-C)"


def _signal_status(signum: int | None) -> int:
    """The shell's convention: 128 + the signal (SIGINT 130, SIGTERM 143)."""
    return 143 if signum == signal.SIGTERM else 130


def _main(argv: Sequence[str] | None, signals: StopSignals) -> int:
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    name = command_named(argv)
    with signals_held():  # the command's module (numpy, the SDKs) is imported here
        parser = build_parser([name] if name else [])
    args = parser.parse_args(argv)
    module = importlib.import_module(COMMANDS[args.command])
    check = getattr(module, "check_arguments", None)
    if check is not None:  # what argparse cannot say, said in its words (one line, exit 2)
        check(parser.commands[args.command], args)
    if not args.debug:  # an error is one line: no RuntimeWarning or library warning around it (--debug shows them)
        warnings.simplefilter("ignore")
    from gaitbot.bus.base import BusError  # imported here: the bus room brings the vendor SDKs and numpy

    try:
        return module.run(args)
    except BrokenPipeError:
        return _closed_output()
    except (KeyboardInterrupt, Terminated):  # before or after a session (a session handles its own)
        if args.debug:
            raise
        print(f"gaitbot {args.command}: {_signal_words(signals.first_signal)}; nothing more was sent", file=sys.stderr)
        return _signal_status(signals.first_signal)
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
    sys.exit(main(as_program=True))
