#!/usr/bin/env python3
"""Check a trajectory (.csv/.npz) or a bus recording (.jsonl) against a robot's limits.

A thin script around ``gaitbot check``: the same parser, code, arguments and exit status (0 everything
holds, 1 a limit is broken, 2 unreadable input with one line on stderr).

    python tools/check_trajectory.py walk.csv --robot ax12a-biped
    python tools/check_trajectory.py run.jsonl --json [--allow-partial] [--debug]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a source checkout too


def main(argv: list[str] | None = None) -> int:
    from gaitbot.app.cli import main as gaitbot_main

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = ["--debug"] if "--debug" in argv else []
    return gaitbot_main([*debug, "check", *[a for a in argv if a != "--debug"]])


if __name__ == "__main__":
    sys.exit(main())
