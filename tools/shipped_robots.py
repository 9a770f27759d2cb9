"""The shipped robot configs side by side, read from the files themselves (docs/robot-config.md).

    python tools/shipped_robots.py              # the table
    python tools/shipped_robots.py --markdown   # the docs' figure (docs/robot-config.md)

The docs quote no config value by hand: a value that changes in config/ changes this table, and the figure
test (tests/docs/test_figures.py) fails until the page says so.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names  # noqa: E402

HEADER = ("robot", "walker", "joints a leg", "servos", "bus", "cycle s", "longest step m", "full torque at deg",
          "steers", "IMU")


def _bus(config) -> str:
    if config.bus.backend == "dynamixel":
        return f"Dynamixel {config.bus.protocol:.1f}, {config.bus.baudrate:,} baud"
    return f"{config.bus.backend.capitalize()}, {config.bus.baudrate:,} baud"


def row(name: str) -> tuple[str, ...]:
    """One robot's row, every value read from its loaded config."""
    config = load_robot_config(resolve_config(name))
    walking = len(config.walking_joints) // 2
    held = len(config.held_joints) // 2
    servos = ", ".join(sorted({joint.model.name for joint in config.joints}))
    stiffness = config.servo.full_torque_error_deg
    return (
        name,
        "balanced" if config.is_3d else ("planar, on a boom" if config.boom else "planar"),
        f"{walking}" + (f" (+{held} held)" if held else ""),
        f"{len(config.joints)} x {servos}",
        _bus(config),
        f"{config.gait.cycle_s:g}",
        f"{config.gait.max_step_m:g}",
        "factory" if stiffness is None else f"{stiffness:g}",
        "yes" if config.steer is not None else "no",
        config.imu.source,
    )


def markdown(rows) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args()
    rows = [row(name) for name in shipped_config_names()]
    if args.markdown:
        print(f"<!-- figure shipped-robots -->\n{markdown(rows)}\n<!-- /figure -->")
    else:
        print(markdown(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
