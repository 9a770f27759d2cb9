#!/usr/bin/env python3
"""What reading servo health costs on the wire, per frame, for every shipped robot (docs/bring-up.md).

    python tools/health_cost.py                 # at each robot's own baud rate
    python tools/health_cost.py --baud 57600    # at another rate (the X series' factory rate)

A session sends one goal sync write per frame and reads ONE servo back, in turn (gaitbot.stream.session).
Reading that servo's health block (position, voltage, temperature, load) instead of its position alone adds
the bytes printed here; the frame budget gaitbot checks every config against (gaitbot.servos.budget: the write
plus a read-back of EVERY servo, 30 % margin) already counts more than that, so health reads fit the same
budget. Bytes at 10 bits each, plus one return delay (the assumed 500 us) per status packet.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a source checkout too

from gaitbot.servos.budget import BITS_PER_BYTE, DEFAULT_RETURN_DELAY_S, frame_budget, one_servo_read_back_bytes  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names  # noqa: E402
from gaitbot.servos.health import health_block  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description="Wire cost of the per-frame health read, per shipped robot.")
    parser.add_argument("--baud", type=int, help="bits per second for every robot (default: each robot's own)")
    args = parser.parse_args(argv)
    print(f"{'robot':14s} {'servo':10s} {'baud':>9s} {'block':>9s} {'write B':>7s} {'pos B':>5s} {'health B':>8s} "
          f"{'+us':>5s} {'frame ms':>8s} {'of 16.7':>7s} {'budget B':>8s}")
    for name in shipped_config_names():
        robot = load_robot_config(resolve_config(name))
        model, bus = robot.joints[0].model, robot.bus
        n = len(robot.joints)
        baudrate = args.baud or bus.baudrate
        budget = frame_budget(bus.backend, bus.protocol, model, n, baudrate, read_back=True)
        write = budget.write_bytes
        position = one_servo_read_back_bytes(bus.backend, bus.protocol, model, health=False)
        health = one_servo_read_back_bytes(bus.backend, bus.protocol, model, health=True)
        byte_us = BITS_PER_BYTE / baudrate * 1e6
        frame_ms = ((write + health) * byte_us + DEFAULT_RETURN_DELAY_S * 1e6) / 1000
        block = health_block(model)
        print(f"{name:14s} {model.name:10s} {baudrate:9,d} {f'{block.address}..{block.address + block.length - 1}':>9s} "
              f"{write:7d} {position:5d} {health:8d} {(health - position) * byte_us:5.0f} {frame_ms:8.2f} "
              f"{frame_ms / (1000 / robot.gait.rate_hz):7.1%} {budget.read_bytes:8d}")
        if health > budget.read_bytes:
            print(f"  {name}: the health read does not fit the budgeted read-back", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
