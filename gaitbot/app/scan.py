"""``gaitbot scan``: which servos answer a ping (exit 1 when a configured one is missing)."""

from __future__ import annotations

from gaitbot.app.hardware import refuse_port_in_dry_run, serial_port
from gaitbot.app.options import check_reply_timeout, load_robot
from gaitbot.bus.factory import make_robot_bus


def run(args) -> int:
    refuse_port_in_dry_run(args)
    config = load_robot(args.robot)
    port = serial_port(config, args.port, args.dry_run)
    ids = range(0, 253) if args.all else config.ids
    names = {j.id: j.name for j in config.joints}
    check_reply_timeout(args.reply_timeout_ms)
    bus = make_robot_bus(config, port, dry_run=args.dry_run, reply_timeout_ms=args.reply_timeout_ms)
    with bus:
        found = bus.scan(ids)
    for servo_id in ids if not args.all else found:
        state = "answers" if servo_id in found else "MISSING"
        print(f"id {servo_id:3d}  {names.get(servo_id, '(not in config)'):20s} {state}")
    missing = [i for i in config.ids if i not in found]
    return 1 if missing else 0
