"""The servo emulator's command line (``python tools/servo_emulator.py``; the engine is gaitbot.bus.emulator).

Opens a pty pair, prints the device path (the end a driver opens) as the first line of its output,
and answers on it like a chain of servos until Ctrl-C:

    python tools/servo_emulator.py --robot config/xl430-biped.toml --log goals.jsonl
    python tools/servo_emulator.py --protocol dxl2 --ids 1-6 --late 3:60
    gaitbot walk --robot config/xl430-biped.toml --distance 0.3 --port /dev/pts/N

Faults start after ``--fault-after-frames`` goal frames and ``--fault-after-s`` seconds from the first
packet received (default: at once). docs/emulator.md lists every option.
"""

from __future__ import annotations

import argparse
import math
import sys

from gaitbot.app.cli import OneLineParser
from gaitbot.bus.emulator import FAULT_KINDS, EmulatorConfig, Faults, ServoEmulator, hand_from_trajectory
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.servos.models import servo_model

#: --protocol name -> (backend, protocol, default model)
PROTOCOLS = {"dxl1": ("dynamixel", 1.0, "AX-12A"), "dxl2": ("dynamixel", 2.0, "XL430-W250"),
             "feetech-sts": ("feetech", 1.0, "STS3215"), "feetech-scs": ("feetech", 1.0, "SCS0009")}


def parse_ids(text: str) -> list[int]:
    """``1-6`` / ``1,2,5`` / ``9-16,20`` -> ids."""
    ids: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part:
            low, high = (int(x) for x in part.split("-", 1))
            ids.extend(range(low, high + 1))
        elif part:
            ids.append(int(part))
    if not ids or len(set(ids)) != len(ids) or not all(0 <= i <= 252 for i in ids):
        raise ValueError(f"--ids {text!r}: give distinct ids 0..252, e.g. 1-6 or 1,2,5")
    return ids


def _id_value(text: str, what: str) -> tuple[int, str]:
    servo_id, sep, value = text.partition(":")
    if not sep or not servo_id.strip().isdigit():
        raise ValueError(f"{what} {text!r}: expected ID:VALUE with a servo id, e.g. 3:{value or '60'}")
    return int(servo_id), value


def check_fault_ids(faults: Faults, models) -> None:
    """Every servo a fault names must be on the chain: a fault on a servo that is not there would be a test
    that tests nothing."""
    named = {"--silent": faults.silent, "--late": set(faults.late_s), "--error": set(faults.errors),
             "--corrupt": faults.corrupt_ids or set()}
    for flag, ids in named.items():
        absent = sorted(i for i in ids if i not in models)
        if absent:
            raise ValueError(f"{flag}: servo {', '.join(map(str, absent))} is not on the chain "
                             f"(ids {', '.join(map(str, sorted(models)))})")


def check_numbers(args: argparse.Namespace) -> None:
    """Counts and times that cannot be negative (or not finite), and rates that must be positive."""
    for flag in ("fault_after_frames", "close_after_frames"):
        value = getattr(args, flag)
        if value is not None and value < 0:
            raise ValueError(f"--{flag.replace('_', '-')} must be 0 or more goal frames, got {value}")
    for flag in ("fault_after_s", "close_after_s", "return_delay_us"):
        value = getattr(args, flag)
        if value is not None and not (math.isfinite(value) and 0 <= value <= 1e6):
            raise ValueError(f"--{flag.replace('_', '-')} must be a number within 0..1e6, got {value!r}")
    if args.baudrate is not None and not 0 < args.baudrate <= 100_000_000:
        raise ValueError(f"--baudrate must be a positive bit rate, got {args.baudrate}")
    if args.hand_rate is not None and not (math.isfinite(args.hand_rate) and 0 < args.hand_rate <= 1000):
        raise ValueError(f"--hand-rate must be within 0..1000 Hz, got {args.hand_rate!r}")


def config_from_args(args: argparse.Namespace) -> EmulatorConfig:
    check_numbers(args)
    faults = Faults(after_frames=args.fault_after_frames, after_s=args.fault_after_s,
                    close_after_frames=args.close_after_frames, close_after_s=args.close_after_s)
    faults.silent = set(args.silent or [])
    for item in args.late or []:
        servo_id, value = _id_value(item, "--late")
        try:
            late_ms = float(value)
        except ValueError:
            raise ValueError(f"--late {item!r}: MS must be a number of milliseconds") from None
        if not (math.isfinite(late_ms) and 0 <= late_ms <= 10_000):
            raise ValueError(f"--late {item!r}: MS must be within 0..10000 ms")
        faults.late_s[servo_id] = late_ms / 1000.0
    if args.corrupt:
        fraction, _, which = args.corrupt.partition(":")
        try:
            faults.corrupt_fraction = float(fraction)
            faults.corrupt_ids = {int(which)} if which else None
        except ValueError:
            raise ValueError(f"--corrupt {args.corrupt!r}: expected FRACTION[:ID], e.g. 0.5:3") from None
        if not 0.0 <= faults.corrupt_fraction <= 1.0:
            raise ValueError(f"--corrupt {args.corrupt!r}: the fraction must be within 0..1")
    for item in args.error or []:
        servo_id, value = _id_value(item, "--error")
        kinds = set(value.split("+"))
        if not kinds <= set(FAULT_KINDS):
            raise ValueError(f"--error {item!r}: kinds are {', '.join(FAULT_KINDS)} (join with +)")
        faults.errors[servo_id] = kinds
    if args.robot:
        robot = load_robot_config(resolve_config(args.robot))
        check_fault_ids(faults, robot.models_by_id)
        hand = hand_from_trajectory(robot, args.hand, args.hand_rate) if args.hand else None
        return EmulatorConfig(robot.bus.backend, robot.bus.protocol, robot.models_by_id,
                              args.baudrate or robot.bus.baudrate, faults, args.log, robot.name,
                              {j.name: j.id for j in robot.joints}, args.seed, args.return_delay_us, hand)
    if args.hand:
        raise ValueError("--hand needs --robot (its calibration turns the trajectory's angles into ticks)")
    if not args.protocol:
        raise ValueError("give --robot CONFIG or --protocol dxl1|dxl2|feetech-sts|feetech-scs with --ids")
    backend, protocol, default_model = PROTOCOLS[args.protocol]
    model = servo_model(args.model or default_model)
    if model.family != backend or protocol not in model.protocols:
        raise ValueError(f"--model {model.name} does not speak {args.protocol}")
    models = {i: model for i in parse_ids(args.ids)}
    check_fault_ids(faults, models)
    return EmulatorConfig(backend, protocol, models, args.baudrate or 1_000_000, faults, args.log,
                          seed=args.seed, return_delay_us=args.return_delay_us)


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="servo_emulator", description="Emulate a Dynamixel/Feetech servo chain on a pty "
                                            "(the first line printed is the device path).")
    p.add_argument("--robot", help="robot config (.toml path or shipped name): its bus and servos")
    p.add_argument("--protocol", choices=sorted(PROTOCOLS), help="without --robot: the chain's protocol")
    p.add_argument("--ids", default="1-6", help="without --robot: servo ids, e.g. 1-6 or 1,2,5 (default 1-6)")
    p.add_argument("--model", help="without --robot: servo model (default per protocol)")
    p.add_argument("--baudrate", type=int, help="byte time of replies (default: the config's or 1000000)")
    p.add_argument("--return-delay-us", type=float, help="override every servo's Return Delay Time")
    p.add_argument("--log", help="write every goal packet received to this .jsonl (bus recording format)")
    p.add_argument("--seed", type=int, default=0, help="random seed of --corrupt")
    p.add_argument("--silent", type=int, action="append", metavar="ID", help="this servo never answers")
    p.add_argument("--late", action="append", metavar="ID:MS", help="this servo answers MS ms late")
    p.add_argument("--corrupt", metavar="FRACTION[:ID]", help="damage this fraction of replies (of one servo)")
    p.add_argument("--error", action="append", metavar="ID:KIND[+KIND]",
                   help=f"status error bits on this servo's replies; KIND in {', '.join(FAULT_KINDS)}")
    p.add_argument("--fault-after-frames", type=int, default=0, help="faults start after this many goal frames")
    p.add_argument("--fault-after-s", type=float, default=0.0, help="faults start this long after the first packet")
    p.add_argument("--close-after-frames", type=int, help="the port disappears after this many goal frames")
    p.add_argument("--close-after-s", type=float, help="the port disappears this long after the first packet")
    p.add_argument("--hand", metavar="FILE", help="with --robot: a trajectory (.csv/.npz) a hand plays on the servos "
                   "while their torque is off, one sample per read cycle")
    p.add_argument("--hand-rate", type=float, metavar="HZ", help="advance the --hand script with time at HZ instead")
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        config = config_from_args(args)
    except (ValueError, KeyError, OSError) as exc:
        print(f"servo_emulator: error: {exc}", file=sys.stderr)
        return 2
    emulator = ServoEmulator(config)
    print(emulator.path, flush=True)
    names = sorted({m.name for m in config.models.values()})
    print(f"emulating {len(config.models)} {'/'.join(names)} servos (ids {sorted(config.models)}) on "
          f"{config.backend} protocol {config.protocol}; Ctrl-C to stop", file=sys.stderr, flush=True)
    try:
        emulator.serve()
    except KeyboardInterrupt:
        pass
    finally:
        emulator.stop()
    if emulator.closed_reason:
        print(f"servo_emulator: {emulator.closed_reason}", file=sys.stderr)
    if config.log_path:
        print(f"servo_emulator: {emulator.chain.goal_frames} goal frames logged to {config.log_path}",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
