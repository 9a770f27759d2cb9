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
from gaitbot.app.file_robot import robot_for_file
from gaitbot.app.options import UsageError, load_robot
from gaitbot.bus.recording import is_bus_log, read_header, typed_header
from gaitbot.check.preflight import preflight
from gaitbot.check.recording import check_recording, match_config, robot_for_recording
from gaitbot.robot.calibration_file import CalibrationError, with_sent_calibration
from gaitbot.robot.config import RobotConfig, load_robot_config, resolve_config
from gaitbot.gait.trajectory import load_fast, refuse_truncated_csv


def add_parser(subparsers):
    p = add_command(subparsers, "check")
    p.add_argument("file", help="trajectory (.csv, .npz) or bus recording (.jsonl)")
    robot_options(p, "robot config (default: the robot the file was made or recorded for, else xl430-biped)")
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
    if path.suffix == ".csv" and path.is_file():
        refuse_truncated_csv(path)
    trajectory = load_fast(path)
    config = robot_for_file(path, trajectory.origin, args.robot, getattr(args, "calibration", None))
    report = preflight(config, trajectory, margin, on_boom=bool(getattr(args, "boom", False)))
    if args.json:
        print(json.dumps({"kind": "trajectory", "file": str(path), **report.to_dict()}, indent=2))
    else:
        print(f"{path}: trajectory checked against {config.name}")
        print(report.format_text())
    return 0 if report.ok else 1


def _check_recording(args, path: Path, margin: float) -> int:
    config = robot_of_recording(path, args.robot, getattr(args, "calibration", None))
    report = check_recording(config, path, margin, allow_partial_last_line=bool(getattr(args, "allow_partial", False)))
    if args.json:
        print(json.dumps({**report.to_dict(), "config": str(config.path)}, indent=2))
    else:
        print(report.format_text())
    return 0 if report.ok else 1


def robot_of_recording(path: Path, robot: str | None, calibration: str | None) -> RobotConfig:
    """The config a bus recording is checked against: ``--robot``, else the recording's robot; decoded with
    the calibration the header says it was sent with (a ``--calibration`` that differs is refused), or, in a
    recording written before headers kept it, ``--calibration`` or the one beside the config."""
    header = read_header(path)
    sent = header.get("calibration")
    if sent is None:
        return robot_for_recording(path, robot, lambda name: load_robot(name, calibration))
    config = robot_for_recording(path, robot, lambda name: load_robot_config(resolve_config(name)))
    match_config(path, typed_header(header), config)  # another robot's recording is named so, not by its ticks
    if calibration is not None:
        given = load_robot(str(config.path), calibration)
        for joint in given.joints:
            was = sent["joints"].get(joint.name)
            if was is not None and (was["zero_tick"], was["direction"]) != (joint.zero_tick, joint.direction):
                raise UsageError(f"--calibration {calibration}: {path} was sent with another calibration "
                                 f"({joint.name}: zero tick {was['zero_tick']}, direction {was['direction']}; this "
                                 f"file gives {joint.zero_tick}, {joint.direction}); leave --calibration out to use "
                                 f"the recording's")
    try:
        return with_sent_calibration(config, sent, path)
    except CalibrationError as exc:
        raise UsageError(f"{path}: header calibration: {exc}") from None
