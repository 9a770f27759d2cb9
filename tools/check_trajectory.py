#!/usr/bin/env python3
"""Check a trajectory (.csv/.npz) or a bus recording (.jsonl) against a robot's limits.

A thin script around the code of ``gaitbot check`` (gaitbot.check_command.run_check), with the
same arguments and exit status: 0 everything holds, 1 a limit is broken, 2 unreadable input
(one line on stderr). ``--allow-partial`` checks a recording whose last line a crash cut short.

    python tools/check_trajectory.py walk.csv --robot ax12a-biped
    python tools/check_trajectory.py run.jsonl --json
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a source checkout too


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="check_trajectory.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    parser.add_argument("--robot", help="robot config (default: a recording's own robot, else xl430-biped)")
    parser.add_argument("--json", action="store_true", help="print the result as one JSON object")
    parser.add_argument("--margin-deg", type=float, default=0.0, help="warn within this many degrees of a limit")
    parser.add_argument("--allow-partial", action="store_true",
                        help="recordings: ignore a truncated last line (with a warning) instead of refusing the file")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    args = parser.parse_args(argv)

    from gaitbot.check_command import run_check
    from gaitbot.errors import USER_ERRORS

    try:
        return run_check(args)
    except USER_ERRORS as exc:
        if args.debug:
            raise
        print(f"check_trajectory.py: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
