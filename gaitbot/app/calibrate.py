"""``gaitbot calibrate``: each joint's zero tick and direction measured on the robot, written to a calibration file.

The person holds the robot (torque off) in its zero pose, then bends each joint in its positive direction
when asked (gaitbot/stream/calibrate.py runs the steps; gaitbot/robot/joint_directions.py says them in words).
The file (gaitbot/robot/calibration_file.py, docs/file-formats.md) is checked against the config before it
is written: a zero tick with which a configured limit falls outside the servo's range is refused with the
range. Nothing is written to a servo but Torque Enable = 0.
"""

from __future__ import annotations

import sys
from pathlib import Path

from gaitbot.app.arguments import REPLY_TIMEOUT_HELP, add_command
from gaitbot.app.hardware import serial_port, warn_about_latency
from gaitbot.app.options import UsageError, check_reply_timeout, load_robot
from gaitbot.app.outputs import output_path, write_output
from gaitbot.bus.factory import make_robot_bus
from gaitbot.robot.calibration_file import (CalibrationFile, JointCalibration, apply_calibration,
                                            calibration_path_for, write_calibration)
from gaitbot.robot.joint_directions import positive_motion
from gaitbot.stream.calibrate import CalibrationJoint, CalibrationStopped, calibrate_session

ZERO_POSE = ("Hold the robot in its zero pose: legs straight, feet flat and parallel, torso upright "
             "(docs/bring-up.md has a picture). Press Enter.")
BEND = ("{joint}: {words}, by 20 degrees or more (the joints bent before may stay bent or go back to zero). "
        "Hold it there. Press Enter.")
QUESTION = "Turn torque off on {n} servos? The legs will go limp: hold the robot. [y/N] "


def _check_output(out: Path) -> None:
    if out.suffix != ".toml":
        raise UsageError(f"-o {out}: a calibration file is TOML: the name must end in .toml "
                         f"(e.g. {calibration_path_for('robot.toml').name}, found beside robot.toml by name)")


def _wait_for_enter(step: str, words: str) -> None:
    text = ZERO_POSE if step == "zero" else BEND.format(joint=step, words=words[:1].upper() + words[1:])
    print(text, flush=True)
    if not sys.stdin.readline():
        raise CalibrationStopped("no answer on standard input (press Enter at each step); nothing written")


def _confirm(yes: bool):
    def confirm(n: int) -> bool:
        if yes:
            return True
        print(QUESTION.format(n=n), end="", flush=True)
        answer = sys.stdin.readline()
        if not answer:
            print()
        return answer.strip().lower() in ("y", "yes")
    return confirm


def add_parser(subparsers):
    p = add_command(subparsers, "calibrate")
    p.add_argument("--robot", help="robot config (default xl430-biped)")
    p.add_argument("-o", "--output", help="calibration file to write (.toml; default: where every command finds "
                   "it, beside your config as <config stem>.calibration.toml, for a shipped robot in this folder)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="turn torque off without asking")
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP)
    return p


def run(args) -> int:
    config = load_robot(args.robot, None)  # measured as the config describes the servos, without any calibration
    out = Path(args.output) if args.output is not None else calibration_path_for(config.path)
    _check_output(out)
    output_path(out, "-o", args)
    check_reply_timeout(args.reply_timeout_ms)
    port = serial_port(config, args.port, dry_run=False)
    warn_about_latency(port)
    bus = make_robot_bus(config, port, reply_timeout_ms=args.reply_timeout_ms)
    joints = [CalibrationJoint(j.name, j.id, j.model, j.min_deg, j.max_deg) for j in config.joints]
    results = calibrate_session(bus, joints, ask=_wait_for_enter, confirm=_confirm(args.yes), words=positive_motion)
    if results is None:
        print(f"{config.name}: calibration cancelled: nothing was written, torque left as it was.")
        return 0
    calibrated = [JointCalibration(r.name, r.id, r.model_name, r.zero_tick, r.direction, round(r.moved_deg, 1))
                  for r in results]
    apply_calibration(config, CalibrationFile(out, config.name, tuple(calibrated)))  # refuses what cannot hold
    comment = (f"gaitbot calibrate --robot {config.path}: zero ticks and directions of {config.name}'s servos,\n"
               "measured on the robot (docs/file-formats.md). Applied on top of the config by --calibration,\n"
               "or found by default as " + str(calibration_path_for(config.path)) + ".")
    write_output(out, lambda path: write_calibration(path, config.name, calibrated, comment=comment))
    print(f"{'joint':20s} {'id':>4s} {'zero tick':>9s} {'direction':>9s} {'bent deg':>8s}  was (config)")
    by_name = {j.name: j for j in config.joints}
    for r in results:
        was = by_name[r.name]
        print(f"{r.name:20s} {r.id:4d} {r.zero_tick:9d} {r.direction:+9d} {r.moved_deg:8.1f}  "
              f"{was.zero_tick} / {was.direction:+d}")
        for note in r.notes:
            print(f"warning: {r.name}: {note}", file=sys.stderr)
    own = calibration_path_for(config.path)
    print(f"wrote {out}: {len(results)} joints of {config.name}; torque stays off. "
          + (f"Every command given --robot {config.path} applies it from there (or give --calibration FILE)."
             if out.resolve() == own.resolve() else
             f"Use it with --calibration {out}, or name it {own} to have it found by default"))
    return 0
