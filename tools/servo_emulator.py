#!/usr/bin/env python3
"""A servo chain on a pseudo-terminal: run ``gaitbot walk --port <pty>`` without hardware.

    python tools/servo_emulator.py --robot config/xl430-biped.toml [--log goals.jsonl] [faults...]
    python tools/servo_emulator.py --protocol dxl2 --ids 1-6 --late 3:60
    python tools/servo_emulator.py --robot config/xl430-biped.toml --factory-fresh --one-at-a-time

A thin script around gaitbot.app.emulator (the command line) and gaitbot.emulator (the engine,
importable from tests); docs/emulator.md describes the options.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a source checkout too

from gaitbot.app.emulator import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
