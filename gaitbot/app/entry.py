"""The program's entry point (the ``gaitbot`` console script and ``python -m gaitbot``).

Its first act is to catch SIGINT and SIGTERM: until then a Ctrl-C is Python's KeyboardInterrupt, and
one that lands while the command line is still being imported (a tenth of a second) would print a
traceback. Caught here, a signal during the imports only is noted, and the command ends at once
with one line and exit 130 (143 for SIGTERM), nothing sent. This module imports nothing else of
gaitbot before that, and ``gaitbot`` and ``gaitbot.app`` import next to nothing.
"""

from __future__ import annotations

import signal
import sys


def main(argv: list[str] | None = None) -> int:
    early: list[int] = []
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda received, _frame: early.append(received))
    from gaitbot.app.cli import main as run_command_line  # the heavy part: signals are only noted meanwhile

    return run_command_line(argv, early_signals=early, as_program=True)


if __name__ == "__main__":
    sys.exit(main())
