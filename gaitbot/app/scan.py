"""``gaitbot scan``: every servo that answers, at every baud rate of the configured protocol (or ``--baud``).

Per servo: id, baud rate, model by name, firmware, present position (ticks, and as its configured joint's
angle), input voltage, temperature, torque, hardware errors in words; then the configured joints that did
not answer (at their id, the config's baud rate and model; each is pinged once more on its own before it is
called missing). Reads only (gaitbot/bus/bringup.py). Exit 0 when every configured joint answered as
configured, 1 otherwise; ``--json`` prints one object.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection, Mapping

from gaitbot.app.arguments import add_command, bus_options, robot_options
from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port
from gaitbot.app.options import UsageError, check_reply_timeout, load_robot
from gaitbot.bus.bringup import ServoReport, describe_servo, survey
from gaitbot.bus.factory import make_probe_bus, stand_ticks_by_id
from gaitbot.app.progress import progress
from gaitbot.servos import common_baud_rates, max_servo_id, vendor


def survey_shown(probe, rates, what: str, expected: Mapping[int, Collection[int]] | None = None) -> list:
    """``survey`` with a progress bar on a terminal (one step a PING; a broadcast ping is one step), the rate
    being searched and the servos found so far beside it (``expected``: survey's)."""
    broadcast = probe.vendor.BROADCAST_PING.get(probe.protocol) is not None
    per_rate = 1 if broadcast else max_servo_id(probe.backend, probe.protocol) + 1
    found = []

    def after_rate(result) -> None:
        found.extend(result.found)
        bar.set_postfix_str(f"{result.baudrate:,} baud done, {len(found)} found")

    with progress(what, total=len(rates) * per_rate, unit="ping") as bar:
        return survey(probe, rates, on_baud=after_rate, on_ping=lambda _servo_id: bar.update(), expected=expected)


def _joint_of(config, report: ServoReport):
    for j in config.joints:
        if j.id == report.found.servo_id and report.found.baudrate == config.bus.baudrate:
            return j
    return None


def _angle_deg(joint, ticks: int) -> float:
    return math.degrees((ticks - joint.zero_tick) / (joint.direction * joint.model.ticks_per_rad))


def _row(config, report: ServoReport) -> dict:
    found, health, joint = report.found, report.health, _joint_of(config, report)
    row = {"id": found.servo_id, "baudrate": found.baudrate, "model": found.model_name,
           "model_number": found.model_number, "firmware": report.firmware,
           "position_ticks": health.position_ticks if health else None,
           "joint": joint.name if joint else None,
           "angle_deg": round(_angle_deg(joint, health.position_ticks), 2) + 0.0 if joint and health else None,
           "voltage_v": health.voltage_v if health else None, "temperature_c": health.temperature_c if health else None,
           "load_pct": health.load_pct if health else None,
           "torque": None if report.torque_on is None else ("on" if report.torque_on else "off"),
           "hardware_errors": list(report.errors), "problems": list(report.problems)}
    if joint is not None and joint.model.name != found.model_name:
        row["problems"].append(f"the config says {joint.model.name} for {joint.name}")
    return row


def _missing(config, rows: list[dict]) -> list[dict]:
    answered = {(r["id"], r["baudrate"], r["model"]) for r in rows}
    return [{"joint": j.name, "id": j.id, "model": j.model.name, "baudrate": config.bus.baudrate}
            for j in config.joints if (j.id, config.bus.baudrate, j.model.name) not in answered]


def _text(value, fmt: str = "{}") -> str:
    return "-" if value is None else fmt.format(value)


def add_parser(subparsers):
    p = add_command(subparsers, "scan")
    robot_options(p, "robot config: its protocol, and the joints to match (default xl430-biped)")
    p.add_argument("--baud", type=int, help="scan this baud rate only (default: every rate a servo of the "
                   "configured protocol can run at)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    bus_options(p, "scan the mock bus (the config's servos at its baud rate)")
    return p


def run(args) -> int:
    refuse_port_in_dry_run(args)
    config = load_robot(args.robot, getattr(args, "calibration", None))
    check_reply_timeout(args.reply_timeout_ms)
    backend, protocol = config.bus.backend, config.bus.protocol
    if args.baud is not None:
        if args.baud not in vendor(backend).SDK_BAUDRATES:
            raise UsageError(f"--baud {args.baud}: the {backend} SDK does not offer it (it offers "
                             f"{', '.join(str(r) for r in vendor(backend).SDK_BAUDRATES)})")
        rates = (args.baud,)
    else:
        rates = common_baud_rates(backend, protocol)
    port = serial_port(config, args.port, args.dry_run)
    probe = make_probe_bus(backend, protocol, port, dry_run=args.dry_run, models=config.models_by_id,
                           baudrate=config.bus.baudrate, reply_timeout_ms=args.reply_timeout_ms,
                           start_ticks=stand_ticks_by_id(config))
    if not args.json:
        print(f"{config.name}: scanning {backend} protocol {protocol:g} on {port} at "
              f"{', '.join(f'{r:,}' for r in rates)} baud", flush=True)
    with probe:
        results = survey_shown(probe, rates, "scan", expected={config.bus.baudrate: [j.id for j in config.joints]})
        reports = [describe_servo(probe, s) for r in results for s in r.found]
    rows = [_row(config, r) for r in reports]
    missing = _missing(config, rows)
    damaged = {r.baudrate: r.damaged for r in results if r.damaged}
    if args.json:
        print(json.dumps({"robot": config.name, "port": port, "backend": backend, "protocol": protocol,
                          "baud_rates": list(rates), "servos": rows, "missing_joints": missing,
                          "damaged_replies": {str(k): v for k, v in damaged.items()}}, indent=2))
        return 1 if missing else 0
    print(f"{'id':>3s} {'baud':>9s} {'model':11s} {'fw':>4s} {'ticks':>6s} {'joint':18s} {'angle':>7s} "
          f"{'volts':>5s} {'temp':>4s} {'load':>6s} {'torque':6s} hardware errors")
    for r in rows:
        errors = ", ".join(r["hardware_errors"]) or "none"
        print(f"{r['id']:3d} {r['baudrate']:9,d} {_text(r['model'] or r['model_number']):11s} "
              f"{_text(r['firmware']):>4s} {_text(r['position_ticks']):>6s} {_text(r['joint']):18s} "
              f"{_text(r['angle_deg'], '{:.1f}'):>7s} {_text(r['voltage_v'], '{:.1f}'):>5s} "
              f"{_text(r['temperature_c'], '{:.0f}'):>4s} {_text(r['load_pct'], '{:.1f}%'):>6s} {_text(r['torque']):6s} "
              f"{errors}" + "".join(f"; {p}" for p in r["problems"]))
    if not rows:
        print("no servo answered")
    for rate, n in damaged.items():
        what = "a garbled reply" if n == 1 else f"{n} garbled replies"
        print(f"warning: {what} at {rate:,} baud: two servos share an id there (or the wiring is bad)")
    for m in missing:
        print(f"missing: {m['joint']} (id {m['id']}, {m['model']}, {m['baudrate']:,} baud) did not answer")
    return 1 if missing else 0
