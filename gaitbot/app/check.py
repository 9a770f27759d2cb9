"""``gaitbot check``: a trajectory or a recording against a robot's limits (exit 0 ok, 1 broken, 2 unreadable).

``run(args)`` reads ``args.file``, ``args.robot``, ``args.json``, ``args.margin_deg`` and, when the
command line offers it, ``args.allow_partial`` (check a recording whose last line was cut short by a
crash, with a warning, instead of refusing it). Unreadable input raises a ``UserError`` (one line,
exit 2); ``tools/check_trajectory.py`` calls the same. Files are read by their formats' own readers:
a bus recording (gaitbot.bus.recording.is_bus_log) or a trajectory (``.csv``/``.npz``, gaitbot.gait.trajectory;
a ``.csv`` whose last line has no newline is taken as truncated). docs/checking.md says what is checked.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from gaitbot.app.arguments import add_command, robot_options
from gaitbot.app.options import UsageError, load_robot
from gaitbot.bus.recording import is_bus_log
from gaitbot.check.preflight import preflight
from gaitbot.check.recording import check_recording, robot_for_recording
from gaitbot.gait.trajectory import load_fast, refuse_truncated_csv


def add_parser(subparsers):
    p = add_command(subparsers, "check")
    p.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    robot_options(p, "robot config (default: a recording's own robot, else xl430-biped)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--margin-deg", type=float, default=0.0, metavar="DEG",
                   help="warn within this many degrees of a limit (default 0)")
    p.add_argument("--boom", action="store_true",
                   help="the robot walks on a boom: do not check its balance (ZMP against the support polygon)")
    p.add_argument("--allow-partial", action="store_true",
                   help="recordings: ignore a truncated last line (with a warning), e.g. after a crash")
    return p


def run(args) -> int:
    margin = args.margin_deg if args.margin_deg is not None else 0.0
    if not (math.isfinite(margin) and margin >= 0):
        raise UsageError(f"--margin-deg must be a finite number of degrees >= 0, got {margin!r}")
    path = Path(args.file)
    if is_bus_log(path):
        return _check_recording(args, path, margin)
    return _check_trajectory_file(args, path, margin)


def _check_trajectory_file(args, path: Path, margin: float) -> int:
    config = load_robot(args.robot, getattr(args, "calibration", None))
    if path.suffix == ".csv" and path.is_file():
        refuse_truncated_csv(path)
    report = preflight(config, load_fast(path), margin, on_boom=bool(getattr(args, "boom", False)))
    if args.json:
        print(json.dumps({"kind": "trajectory", "file": str(path), **report.to_dict()}, indent=2))
    else:
        print(f"{path}: trajectory checked against {config.name}")
        print(report.format_text())
    return 0 if report.ok else 1


def _check_recording(args, path: Path, margin: float) -> int:
    calibration = getattr(args, "calibration", None)
    config = robot_for_recording(path, args.robot, lambda robot: load_robot(robot, calibration))
    report = check_recording(config, path, margin, allow_partial_last_line=bool(getattr(args, "allow_partial", False)))
    if args.json:
        print(json.dumps({**report.to_dict(), "config": str(config.path)}, indent=2))
    else:
        print(report.format_text())
    return 0 if report.ok else 1
