"""What steering costs per 60 Hz frame: the online balanced walker fed one planned step at a time.

A drive's loop, without the input: every frame, if less than LOOKAHEAD_S of steps is queued, the footstep
planner plans the next step from the current command (gaitbot.gait.steer.planner) and the walker appends it
(rerunning its first preview stage over the look-ahead); then ``next_frame``. The command changes every
few seconds (a turn, a sidestep, an arc, forward). Prints the per-frame time (p50, p99, max, ms, wall
clock on this machine, one thread) with and without the frames that appended a step, and a step's
planning time. With ``--spread`` the walker spreads each append's replan over the frames after it
(``append_footstep(..., spread=True)`` and ``work()`` every other frame, as ``gaitbot drive`` does).

    python tools/bench_steer.py [--robot op3] [--seconds 30] [--spread] [--cpu]

``--cpu``: the process's CPU time (time.process_time) instead of the wall clock, whose tail on a shared
machine is the scheduler's.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

COMMANDS = ((0.0, 0.0, 12.0), (0.0, 0.03, 0.0), (0.04, 0.0, 8.0), (0.05, 0.0, 0.0), (-0.04, 0.0, 0.0))
LOOKAHEAD_S = 1.2


def main(argv=None) -> int:
    from gaitbot.app.options import load_robot
    from gaitbot.gait.steer.command import VelocityCommand
    from gaitbot.robot.balanced_walk import balanced_gait_settings, balanced_walker
    from gaitbot.robot.steered_walk import footstep_planner

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="op3")
    p.add_argument("--seconds", type=float, default=30.0)
    p.add_argument("--spread", action="store_true", help="spread each replan over the next frames (gaitbot drive)")
    p.add_argument("--cpu", action="store_true", help="CPU time (time.process_time) instead of the wall clock")
    args = p.parse_args(argv)
    clock = time.process_time if args.cpu else time.perf_counter
    config = load_robot(args.robot)
    gait = balanced_gait_settings(config)
    walker = balanced_walker(config, gait)
    planner = footstep_planner(config, gait)
    rate = walker.rate_hz
    frames, plan_times, appended = [], [], []
    k = 0
    while k < args.seconds * rate:
        t0 = clock()
        queued_s = walker.planned_frames / rate - k / rate
        added = False
        if queued_s < LOOKAHEAD_S:
            command = VelocityCommand(*COMMANDS[int(k / rate / 6.0) % len(COMMANDS)])
            p0 = clock()
            step = planner.next_step(command, walker.next_swing_side)
            plan_times.append(clock() - p0)
            walker.append_footstep(step.foothold, step.length_m, spread=args.spread)
            added = True
        elif args.spread:
            walker.work()
        frame = walker.next_frame()
        frames.append(clock() - t0)
        appended.append(added)
        k += 1
        if frame is None:
            break
    f = 1e3 * np.array(frames)
    a = np.array(appended)
    how = "each replan spread over the frames after it" if args.spread else "each replan at once"
    print(f"{args.robot}: {len(f)} frames ({len(f) / rate:.0f} s), {a.sum()} steps appended while walking ({how}; "
          f"{'CPU' if args.cpu else 'wall'} time)")
    for label, x in (("every frame", f), ("frames without an append", f[~a]), ("frames that appended a step", f[a])):
        print(f"  {label}: p50 {np.percentile(x, 50):.2f} ms, p99 {np.percentile(x, 99):.2f} ms, max {x.max():.2f} ms")
    q = 1e3 * np.array(plan_times)
    print(f"  planning one step: p50 {np.percentile(q, 50):.2f} ms, max {q.max():.2f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
