"""``gaitbot setup``: new servos, connected one at a time, given the ids and baud rate of the robot config.

For each joint (or each ``--joint``): "connect only the servo for knee_pitch_left, press Enter"; the bus is
surveyed at every baud rate that servo model can run at (gaitbot/bus/probe.py, bringup.py); exactly one
servo must answer, of the joint's model; it gets the joint's id and the config's baud rate (torque off, the
Feetech lock, ID, Baud Rate; nothing else) and both are read back. More than one servo on the bus, or a
servo of another model, is refused (one line, exit 2) with nothing written. docs/bring-up.md.
"""

from __future__ import annotations

import sys

from gaitbot.app.arguments import REPLY_TIMEOUT_HELP, add_command, robot_options
from gaitbot.app.hardware import serial_port, warn_about_latency
from gaitbot.app.options import UsageError, check_reply_timeout, load_robot
from gaitbot.bus.base import BusError
from gaitbot.app.scan import survey_shown
from gaitbot.bus.bringup import assign_id_and_baud
from gaitbot.bus.factory import make_probe_bus
from gaitbot.robot.calibration_file import calibration_path_for
from gaitbot.servos import baud_rates, baud_register_value, common_baud_rates, max_servo_id

PROMPT = ("Connect only the servo for {joint} ({model}; it becomes id {id} at {baud:,} baud), then press Enter.")


class NoServo(BusError):
    """Nothing answered at any baud rate."""


def _rates(rates) -> str:
    return ", ".join(f"{r:,}" for r in rates)


def selected_joints(config, names: list[str] | None):
    """The joints to set up: every one of the config, in its order, or those named by --joint."""
    if not names:
        return list(config.joints)
    known = {j.name: j for j in config.joints}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise UsageError(f"--joint {unknown[0]}: no such joint in {config.path} (joints: {', '.join(known)})")
    return [known[n] for n in dict.fromkeys(names)]


def add_parser(subparsers):
    p = add_command(subparsers, "setup")
    robot_options(p, "robot config: the ids, models and baud rate to give (default xl430-biped)")
    p.add_argument("--joint", action="append", metavar="NAME", help="set up this joint only (repeat for several; "
                   "default: every joint, in the config's order)")
    p.add_argument("--port", help="serial port (default: the robot config's)")
    p.add_argument("--yes", action="store_true", help="do not wait for Enter: the servo is already connected")
    p.add_argument("--reply-timeout-ms", type=float, metavar="MS", help=REPLY_TIMEOUT_HELP + "; a short one (5) "
                   "speeds up the search, which tries every id at every baud rate")
    return p


def run(args) -> int:
    config = load_robot(args.robot, getattr(args, "calibration", None))
    joints = selected_joints(config, args.joint)
    baud = config.bus.baudrate
    for joint in joints:
        if baud_register_value(joint.model.name, baud) is None:
            held = _rates(baud_rates(joint.model.name).values())
            raise UsageError(f"{config.path}: bus.baudrate: a {joint.model.name} ({joint.name}) cannot run at "
                             f"{baud:,} baud (its Baud Rate register holds {held})")
    check_reply_timeout(args.reply_timeout_ms)
    port = serial_port(config, args.port, dry_run=False)
    warn_about_latency(port)
    backend, protocol = config.bus.backend, config.bus.protocol
    probe = make_probe_bus(backend, protocol, port, reply_timeout_ms=args.reply_timeout_ms)
    done = 0
    with probe:
        for joint in joints:
            model = joint.model
            if not args.yes:
                print(PROMPT.format(joint=joint.name, model=model.name, id=joint.id, baud=baud), flush=True)
                if not sys.stdin.readline():
                    raise UsageError(f"setup of {joint.name} stopped: no answer on standard input (press Enter once "
                                     "its servo is the only one connected, or give --yes); nothing written")
            rates = common_baud_rates(backend, protocol, [model.name])
            print(f"{joint.name}: looking for a servo at ids 0..{_max_id(probe)} and {_rates(rates)} baud", flush=True)
            results = survey_shown(probe, rates, joint.name)
            found = [s for r in results for s in r.found]
            damaged = {r.baudrate: r.damaged for r in results if r.damaged}
            if len(found) > 1 or damaged:
                seen = [f"id {s.servo_id} at {s.baudrate:,} baud ({s.model_name or s.model_number})" for s in found]
                seen += [f"{_garbled(n)} at {rate:,} baud (servos answering at once)" for rate, n in damaged.items()]
                raise UsageError(f"setup of {joint.name} refused: more than one servo answers ({'; '.join(seen)}); "
                                 f"connect only the servo for {joint.name} and run gaitbot setup --joint {joint.name}; "
                                 "nothing written")
            if not found:
                raise NoServo(f"setup of {joint.name}: no servo answers at any of {_rates(rates)} baud; check its "
                              f"power and cable (and that it is a {model.name})")
            servo = found[0]
            if servo.model_name != model.name:
                raise UsageError(f"setup of {joint.name} refused: the servo connected is a "
                                 f"{servo.model_name or f'model number {servo.model_number}'} (id {servo.servo_id} "
                                 f"at {servo.baudrate:,} baud), the config says {model.name}; nothing written")
            if (servo.servo_id, servo.baudrate) == (joint.id, baud):
                print(f"{joint.name}: already id {joint.id} at {baud:,} baud ({model.name}); nothing written")
                done += 1
                continue
            assignment = assign_id_and_baud(probe, servo, model, joint.id, baud)
            writes = ", ".join(f"{name} = {value}" for name, value in assignment.writes)
            print(f"{joint.name}: {model.name} found at id {servo.servo_id}, {servo.baudrate:,} baud; now id "
                  f"{assignment.servo_id} at {assignment.baudrate:,} baud (read back). Written: {writes}", flush=True)
            done += 1
    robot = args.robot or config.name
    print(f"{config.name}: {done} of {len(joints)} servos set up; next, with every servo connected: gaitbot scan "
          f"--robot {robot}, then gaitbot calibrate --robot {robot} (it writes "
          f"{calibration_path_for(config.path)}, where every command finds it)")
    return 0


def _max_id(probe) -> int:
    return max_servo_id(probe.backend, probe.protocol)


def _garbled(n: int) -> str:
    return "a garbled reply" if n == 1 else f"{n} garbled replies"
