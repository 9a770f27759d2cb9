"""The servo emulator's command line (``python tools/servo_emulator.py``; the engine is gaitbot.emulator).

Opens a pty pair, prints the device path (the end a driver opens) as the first line of its output,
and answers on it like a chain of servos until Ctrl-C or SIGTERM:

    python tools/servo_emulator.py --robot config/xl430-biped.toml --log goals.jsonl
    python tools/servo_emulator.py --protocol dxl2 --ids 1-6 --late 3:60
    gaitbot walk --robot config/xl430-biped.toml --distance 0.3 --port /dev/pts/N
    python tools/servo_emulator.py --robot xl430-biped --factory-fresh --one-at-a-time   # for gaitbot setup
    python tools/servo_emulator.py --robot xl430-biped --load 3:60 --temperature 3:60 --heat-rate 2

Faults (and the supply's sag) start after ``--fault-after-frames`` goal frames and ``--fault-after-s``
seconds from the first packet received (default: at once). With ``--one-at-a-time``, each line read on
standard input (Enter) unplugs the servo connected now and plugs in the next, and after the last one
connects them all (the whole chain, for gaitbot scan and calibrate). ``--state FILE`` keeps the servos'
EEPROM across restarts; ``--hand-calibrate`` stands in for the person gaitbot calibrate asks to bend the
joints. docs/emulator.md lists every option.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import signal
import sys
import threading
from pathlib import Path

from gaitbot.app.cli import OneLineParser
from gaitbot.app.emulator_hand import calibration_hand, mounting_zero_ticks
from gaitbot.bus.factory import stand_ticks_by_id
from gaitbot.emulator import FAULT_KINDS, EmulatorConfig, Faults, Hand, Heat, ServoEmulator, hand_from_ticks
from gaitbot.emulator.state import read_state
from gaitbot.emulator.units import LAYOUTS
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.calibration import trajectory_ticks
from gaitbot.robot.calibration_file import load_robot_with_calibration
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.servos import baud_rates, baud_register_value
from gaitbot.servos.models import servo_model
from gaitbot.bus.imu_device import FAULTS as IMU_FAULTS, ImuDevice
from gaitbot.servos.opencr import OPENCR_OP3_ID

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


def _id_numbers(items, flag: str, low: float, high: float, unit: str) -> dict[int, float]:
    out = {}
    for item in items or []:
        servo_id, value = _id_value(item, flag)
        number = float(value)
        if not low <= number <= high:
            raise ValueError(f"{flag} {item!r}: the value must be within {low:g}..{high:g} {unit}")
        out[servo_id] = number
    return out


def hand_from_trajectory(robot, path: str, rate_hz: float | None = None) -> Hand:
    """A hand playing a trajectory file (.csv/.npz): its angles through the robot's calibration, held
    joints at their hold angle (the emulator room knows no gait: it is given the ticks). Ticks outside a
    servo's encoder range cannot be reported: refused."""
    ticks = trajectory_ticks(robot, Trajectory.load(path))
    for column, joint in enumerate(robot.joints):
        low, high = int(ticks[:, column].min()), int(ticks[:, column].max())
        if low < joint.model.min_tick or high > joint.model.max_tick:
            raise ValueError(f"--hand {path}: {joint.name} goes to ticks {low}..{high}, outside the "
                             f"{joint.model.name}'s {joint.model.min_tick}..{joint.model.max_tick}")
    return Hand({joint.id: ticks[:, column].tolist() for column, joint in enumerate(robot.joints)}, rate_hz)


def imu_from_args(args: argparse.Namespace, config: EmulatorConfig) -> ImuDevice | None:
    """The IMU device of ``--imu`` (its fall and fault), or None; ValueError naming the argument."""
    if not args.imu:
        if args.imu_fall_at_s is not None or args.imu_drop_at_s is not None or args.imu_fault:
            raise ValueError("--imu-fall-at-s, --imu-drop-at-s and --imu-fault need --imu (an IMU on the line)")
        return None
    if config.protocol != 2.0:
        raise ValueError("--imu: the OpenCR answers Dynamixel Protocol 2.0 only (this chain speaks "
                         f"{config.backend} protocol {config.protocol:g})")
    device_id = OPENCR_OP3_ID
    if args.robot:
        imu = load_robot_with_calibration(args.robot, args.calibration).imu
        device_id = imu.device_id if imu.source == "opencr" else OPENCR_OP3_ID
    if device_id in config.models:
        raise ValueError(f"--imu: id {device_id} is a servo's on this chain")
    fall, drop = args.imu_fall_at_s, args.imu_drop_at_s
    for name, value in (("--imu-fall-at-s", fall), ("--imu-drop-at-s", drop)):
        if value is not None and not (math.isfinite(value) and 0 <= value <= 86_400):
            raise ValueError(f"{name} must be within 0..86400 s, got {value}")
    fault, at_s = None, 1.0
    if args.imu_fault:
        fault, _, when = args.imu_fault.partition("@")
        if fault not in IMU_FAULTS:
            raise ValueError(f"--imu-fault {args.imu_fault!r}: KIND is one of {', '.join(IMU_FAULTS)}")
        try:
            at_s = float(when) if when else 1.0
        except ValueError:
            raise ValueError(f"--imu-fault {args.imu_fault!r}: S must be a number of seconds") from None
        if not (math.isfinite(at_s) and 0 <= at_s <= 86_400):
            raise ValueError(f"--imu-fault {args.imu_fault!r}: S must be within 0..86400 s")
    return ImuDevice(device_id=device_id, fall_at_s=fall, drop_at_s=drop, fault=fault, fault_at_s=at_s, seed=args.seed)


def config_from_args(args: argparse.Namespace) -> EmulatorConfig:
    check_numbers(args)
    config = _chain_from_args(args)
    config.heat = Heat(args.ambient, args.heat_rate, args.cool_time)
    if not (args.heat_rate >= 0 and args.cool_time > 0):
        raise ValueError("--heat-rate must be >= 0 C/s and --cool-time a positive number of seconds")
    config.loads_pct = _id_numbers(args.load, "--load", 0.0, 100.0, "%")
    config.temperatures_c = _id_numbers(args.temperature, "--temperature", -20.0, 150.0, "C")
    if args.supply_v is not None and not args.supply_v >= 0:
        raise ValueError(f"--supply-v must be 0 or more volts, got {args.supply_v}")
    if not args.voltage_sag >= 0:
        raise ValueError(f"--voltage-sag must be 0 or more volts per second, got {args.voltage_sag}")
    config.supply_v, config.voltage_sag_v_per_s = args.supply_v, args.voltage_sag
    numbers = _id_numbers(args.model_number, "--model-number", 0, 65535, "(a model number)")
    absent = sorted(set(numbers) - set(config.models))
    if absent:
        raise ValueError(f"--model-number: servo {', '.join(map(str, absent))} is not on the chain")
    config.model_numbers = {servo_id: int(number) for servo_id, number in numbers.items()}
    config.imu = imu_from_args(args, config)
    if args.one_at_a_time and not config.fresh:
        raise ValueError("--one-at-a-time needs --factory-fresh (a chain of new servos, connected one by one)")
    config.one_at_a_time = args.one_at_a_time
    models = list(config.fresh) or list(config.models.values())
    if not config.fresh:
        for model in models:
            if baud_register_value(model.name, config.baudrate) is None:
                rates = ", ".join(f"{r:,}" for r in baud_rates(model.name).values())
                raise ValueError(f"--baudrate {config.baudrate}: a {model.name} cannot run at it (its Baud Rate "
                                 f"register holds {rates})")
    return config


def _chain_from_args(args: argparse.Namespace) -> EmulatorConfig:
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
    if sum(bool(x) for x in (args.hand, args.hand_ticks, args.hand_calibrate)) > 1:
        raise ValueError("give one of --hand, --hand-ticks and --hand-calibrate")
    hand = hand_from_ticks(args.hand_ticks, args.hand_rate) if args.hand_ticks else None
    if args.robot:
        return _robot_chain(args, faults, hand)
    if args.hand_calibrate:
        raise ValueError("--hand-calibrate needs --robot (the joints to bend, in the config's order)")
    if args.hand:
        raise ValueError("--hand needs --robot (its calibration turns the trajectory's angles into ticks)")
    if args.calibration:
        raise ValueError("--calibration needs --robot (it applies to a robot config)")
    if not args.protocol:
        raise ValueError("give --robot CONFIG or --protocol dxl1|dxl2|feetech-sts|feetech-scs with --ids")
    backend, protocol, default_model = PROTOCOLS[args.protocol]
    model = servo_model(args.model or default_model)
    if model.family != backend or protocol not in model.protocols:
        raise ValueError(f"--model {model.name} does not speak {args.protocol}")
    if args.factory_fresh is not None:
        if args.factory_fresh < 1:
            raise ValueError("--factory-fresh N: without --robot, give how many servos (1 or more)")
        return EmulatorConfig(backend, protocol, {}, args.baudrate or 1_000_000, faults, args.log, seed=args.seed,
                              return_delay_us=args.return_delay_us, hand=hand, fresh=(model,) * args.factory_fresh,
                              state_path=args.state)
    restored = _restored(args, backend, protocol)
    models = _models_of(restored) if restored else {i: model for i in parse_ids(args.ids)}
    check_fault_ids(faults, models)
    return EmulatorConfig(backend, protocol, models, args.baudrate or 1_000_000, faults, args.log,
                          seed=args.seed, return_delay_us=args.return_delay_us, hand=hand, restored=restored,
                          state_path=args.state)


def _restored(args: argparse.Namespace, backend: str, protocol: float) -> tuple:
    """The servos of an existing ``--state`` file (none with --factory-fresh: new servos start it afresh)."""
    if not args.state or args.factory_fresh is not None or not Path(args.state).exists():
        return ()
    return tuple(read_state(args.state, backend, protocol))


def _models_of(restored) -> dict:
    ids = [eeprom[LAYOUTS[model.name].id_addr] for model, eeprom in restored]
    return {servo_id: model for servo_id, (model, _eeprom) in zip(ids, restored)}


def _robot_chain(args: argparse.Namespace, faults: Faults, hand: Hand | None) -> EmulatorConfig:
    """The chain of a robot config: its servos (or factory-fresh ones, or those of a --state file), standing
    where the robot stands (the stand pose in its calibrated ticks; with --hand-calibrate, the build's)."""
    robot = load_robot_with_calibration(args.robot, args.calibration)
    check_fault_ids(faults, robot.models_by_id)
    if args.hand:
        hand = hand_from_trajectory(robot, args.hand, args.hand_rate)
    start = stand_ticks_by_id(robot)
    if args.hand_calibrate:
        design = load_robot_config(resolve_config(args.robot))  # the servos as built, not as calibrated
        hand = calibration_hand(design, args.seed)
        start = mounting_zero_ticks(design, args.seed)
    fresh = tuple(j.model for j in robot.joints)[:args.factory_fresh or None] \
        if args.factory_fresh is not None else ()
    restored = _restored(args, robot.bus.backend, robot.bus.protocol)
    models = {} if fresh else (_models_of(restored) if restored else robot.models_by_id)
    return EmulatorConfig(robot.bus.backend, robot.bus.protocol, models,
                          args.baudrate or robot.bus.baudrate, faults, args.log, robot.name,
                          None if fresh else {j.name: j.id for j in robot.joints if j.id in models}, args.seed,
                          args.return_delay_us, hand, fresh=fresh, start_ticks=start, restored=restored,
                          state_path=args.state)


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
    p.add_argument("--hand-ticks", metavar="FILE", help="a hand script in raw ticks: a CSV whose header holds servo "
                   "ids and each row one sample (no calibration involved), e.g. a scripted hand for gaitbot calibrate")
    p.add_argument("--hand-calibrate", action="store_true", help="with --robot: stand in for the person gaitbot "
                   "calibrate asks: the servos are mounted up to a few degrees off the config's zero (drawn from "
                   "--seed), and the hand holds the zero pose, then bends each joint its positive way and lets it back")
    p.add_argument("--state", metavar="FILE", help="keep the servos' EEPROM (ids, baud rates) in FILE: a later run "
                   "with the same FILE has the same servos, all connected (--factory-fresh starts FILE afresh)")
    p.add_argument("--hand-rate", type=float, metavar="HZ", help="advance the --hand script with time at HZ instead")
    p.add_argument("--calibration", metavar="FILE", help="with --robot: a calibration file applied to the config "
                   "(for --hand), as gaitbot's commands apply it")
    p.add_argument("--factory-fresh", type=int, nargs="?", const=0, metavar="N",
                   help="new servos as shipped: every one at id 1 and its factory baud rate (X series 57,600; AX, "
                        "XL-320, Feetech 1,000,000); with --robot one per joint (or the first N), else N of --model")
    p.add_argument("--one-at-a-time", action="store_true", help="with --factory-fresh: only one servo is connected; "
                   "Enter on standard input unplugs it and plugs in the next (as for gaitbot setup)")
    p.add_argument("--load", action="append", metavar="ID:PCT", help="the load (%% of its maximum torque) this "
                   "servo holds while its torque is on; it warms with it (default 0)")
    p.add_argument("--temperature", action="append", metavar="ID:C", help="this servo's temperature at the start "
                   "(default: --ambient)")
    p.add_argument("--ambient", type=float, default=25.0, metavar="C", help="ambient temperature (default 25 C)")
    p.add_argument("--heat-rate", type=float, default=0.5, metavar="C_PER_S",
                   help="warming at full load, C per second (default 0.5; it scales with the load squared)")
    p.add_argument("--cool-time", type=float, default=300.0, metavar="S",
                   help="time constant of cooling towards ambient, seconds (default 300)")
    p.add_argument("--supply-v", type=float, metavar="V", help="supply voltage (default: the servos' usual, "
                   "e.g. 12.0 V for X and AX, 7.4 V for STS3215)")
    p.add_argument("--voltage-sag", type=float, default=0.0, metavar="V_PER_S",
                   help="the supply falls this many volts per second once faults start (--fault-after-*)")
    p.add_argument("--model-number", action="append", metavar="ID:NUMBER", help="this servo reports this model "
                   "number (ping and its Model Number register), e.g. 3:1060 for an XL430-W250 among XM430s")
    p.add_argument("--imu", action="store_true", help="an OP3 OpenCR IMU on the line (at the robot's [imu] id, "
                   "else 200; Protocol 2.0 only): its readings follow a gentle sway of the torso")
    p.add_argument("--imu-fall-at-s", type=float, metavar="S", help="--imu: the torso falls forwards from S "
                   "seconds after the first packet (120 deg/s until flat)")
    p.add_argument("--imu-drop-at-s", type=float, metavar="S", help="--imu: the robot falls freely from S seconds "
                   "after the first packet (level; the accelerometer reads 0 g: the feet's load lost)")
    p.add_argument("--imu-fault", metavar="KIND[@S]", help="--imu: from S seconds (default 1) the IMU is "
                   f"{'|'.join(IMU_FAULTS)} (docs/feedback.md says what a walk does then)")
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
    try:
        with _stopped_by_signals():  # before the path is printed: whoever reads it may signal at once
            print(emulator.path, flush=True)
            _print_banner(config)
            if config.one_at_a_time:
                emulator.start()
                _plug_on_enter(emulator)
                emulator.wait_closed()
            else:
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


def _print_banner(config: EmulatorConfig) -> None:
    """What is emulated, on stderr."""
    if config.fresh:
        names = sorted({m.name for m in config.fresh})
        how = "one at a time (Enter plugs in the next)" if config.one_at_a_time else "all connected"
        print(f"emulating {len(config.fresh)} factory-fresh {'/'.join(names)} servos (all id 1, factory baud rate), "
              f"{how}, on {config.backend} protocol {config.protocol}; Ctrl-C to stop", file=sys.stderr, flush=True)
    else:
        names = sorted({m.name for m in config.models.values()})
        kept = f" as kept in {config.state_path}" if config.restored else ""
        print(f"emulating {len(config.models)} {'/'.join(names)} servos (ids {sorted(config.models)}){kept} on "
              f"{config.backend} protocol {config.protocol}; Ctrl-C to stop", file=sys.stderr, flush=True)


@contextlib.contextmanager
def _stopped_by_signals():
    """Ctrl-C (SIGINT) and SIGTERM end the emulator as its banner says, whatever its parent did: a process
    started in the background of a script inherits SIGINT ignored, and Python then installs no handler of its
    own (a doc test's emulator so ignored its Ctrl-C). The handlers the caller had are put back."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise KeyboardInterrupt

    old = {s: signal.signal(s, stop) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


def _plug_on_enter(emulator: ServoEmulator) -> None:
    """Each line on standard input: unplug the servo connected now and plug in the next."""
    total = len(emulator.chain.units)
    print(f"servo 1 of {total} connected", file=sys.stderr, flush=True)
    for _line in sys.stdin:
        unit = emulator.plug_next()
        if unit is None:
            emulator.connect_all()
            ids = ", ".join(str(u.servo_id) for u in emulator.chain.units)
            print(f"all {total} servos connected: the whole chain, as on the robot (ids {ids})", file=sys.stderr,
                  flush=True)
            continue
        print(f"servo {unit.index + 1} of {total} connected ({unit.model.name}, id {unit.servo_id})",
              file=sys.stderr, flush=True)


if __name__ == "__main__":
    sys.exit(main())
