"""Minutes of random steering commands in gaitbot's own free-floating simulation: falls and figures.

Each robot walks one walk of ``--minutes`` of commands that change every 2 to 5 s (uniform), each a random
velocity anywhere inside the robot's ``[steer]`` limits (vx, vy, wz drawn uniformly within the per-step
limits turned into speeds, the planner clips their combination to its ellipsoid), one in five a stop in
place (a still command), then a stop. Fixed seed: the same walk on any machine. The walk is planned as
``gaitbot generate --commands`` plans it and played with the goals at the stiffness gaitbot writes, as
``gaitbot walk --sim`` sends them. Prints, per robot: commands, steps, simulated time, fell (and when),
and the planned and simulated end poses.

    python tools/steer_random.py [--minutes M] [--seed S] [--robot op3 --robot bioloid] [--markdown]

With ``--markdown`` the lines are printed as the docs' figure block ``steer-random`` (docs/figures.md), without
the planning time (a timing, not a figure).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import steer_judge  # noqa: E402

STILL_SHARE = 0.2


def random_commands(limits, step_s: float, minutes: float, seed: int):
    """Timed commands (gaitbot.gait.steer.command.TimedCommand) ending in a stop."""
    from gaitbot.gait.steer.command import TimedCommand, VelocityCommand

    rng = np.random.default_rng(seed)
    vx_max, vx_min = limits.max_forward_m / step_s, -limits.max_backward_m / step_s
    vy_max = limits.max_side_m / (2 * step_s)
    wz_max = limits.max_turn_deg / (2 * step_s)
    out, t = [], 0.0
    while t < 60.0 * minutes:
        if rng.random() < STILL_SHARE:
            command = VelocityCommand()
        else:
            command = VelocityCommand(float(rng.uniform(vx_min, vx_max)), float(rng.uniform(-vy_max, vy_max)),
                                      float(rng.uniform(-wz_max, wz_max)))
        out.append(TimedCommand(round(t, 3), command))
        t += float(rng.uniform(2.0, 5.0))
    out.append(TimedCommand(round(t, 3), stop=True))
    return out


def run(robot: str, minutes: float, seed: int, timed: bool = True) -> str:
    from gaitbot.app.options import load_robot
    from gaitbot.gait.steer.schedule import CommandSchedule
    from gaitbot.robot.balanced_walk import balanced_gait_settings
    from gaitbot.robot.steered_walk import plan_steered, steering_timing

    config = load_robot(robot)
    gait = balanced_gait_settings(config)
    timing = steering_timing(config, gait)
    commands = random_commands(config.steer, timing.step_frames / timing.rate_hz, minutes, seed)
    start = time.perf_counter()
    plan, steps = plan_steered(config, CommandSchedule.of(commands, "random"), gait, max_steps=100_000)
    planned_s = time.perf_counter() - start
    planned, actual, fell = steer_judge.play_plan_own(robot, plan)
    return (f"{robot}: {len(commands) - 1} commands over {commands[-1].t_s:.0f} s, {len(steps)} steps, "
            f"{plan.walk.t_s[-1]:.0f} s walked{f' (planned in {planned_s:.1f} s)' if timed else ''}; fell: {'YES' if fell else 'no'}; "
            f"end pose planned ({planned[0]:.2f} m, {planned[1]:.2f} m, {planned[2]:.0f} deg), simulated "
            f"({actual[0]:.2f} m, {actual[1]:.2f} m, {actual[2]:.0f} deg)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=10.0)
    p.add_argument("--seed", type=int, default=22)
    p.add_argument("--robot", action="append")
    p.add_argument("--markdown", action="store_true", help="print the lines as the docs' figure block")
    args = p.parse_args(argv)
    if args.markdown:
        print("<!-- figure steer-random -->\n```text")
    for robot in args.robot or ["op3", "bioloid"]:
        print(run(robot, args.minutes, args.seed, timed=not args.markdown), flush=True)
    if args.markdown:
        print("```\n<!-- /figure -->")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
