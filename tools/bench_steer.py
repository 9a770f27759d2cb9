"""What steering costs per 60 Hz frame: the online balanced walker fed one planned step at a time.

A drive's loop, without the input: every frame, if less than LOOKAHEAD_S of steps is queued, the footstep
planner plans the next step from the current command (gaitbot.gait.steer.planner) and the walker appends it
(rerunning its first preview stage over the look-ahead); then ``next_frame``. The command changes every
few seconds (a turn, a sidestep, an arc, forward). Prints the per-frame time (p50, p99, max, ms, wall
clock on this machine, one thread) with and without the frames that appended a step, and a step's
planning time. With ``--spread`` the walker spreads each append's replan over the frames after it
(``append_footstep(..., spread=True)`` and ``work()`` every other frame, as ``gaitbot drive`` does).

    python tools/bench_steer.py [--robot op3] [--seconds 30] [--spread] [--cpu]
    python tools/bench_steer.py --compare     # the spread walk's frames against the at-once walk's (the drive's queue)

``--cpu``: the process's CPU time (time.process_time) instead of the wall clock, whose tail on a shared
machine is the scheduler's.
"""

from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

COMMANDS = ((0.0, 0.0, 12.0), (0.0, 0.03, 0.0), (0.04, 0.0, 8.0), (0.05, 0.0, 0.0), (-0.04, 0.0, 0.0))
LOOKAHEAD_S = 1.2


def walk(config, seconds: float, spread: bool, clock, keep: bool = False, as_drive: bool = False):
    """(rate, per-frame times, planning times, whether each frame appended) of the bench's walk; ``keep``:
    the walker's frames instead of the times; ``as_drive``: a step appended once the last one has started
    (as gaitbot drive queues them: one step ahead) instead of whenever less than LOOKAHEAD_S is queued."""
    from gaitbot.gait.steer.command import VelocityCommand
    from gaitbot.robot.balanced_walk import balanced_gait_settings, balanced_walker
    from gaitbot.robot.steered_walk import footstep_planner

    gait = balanced_gait_settings(config)
    walker = balanced_walker(config, gait)
    planner = footstep_planner(config, gait)
    rate = walker.rate_hz
    frames, plan_times, appended = [], [], []
    k = 0
    while k < seconds * rate:
        t0 = clock()
        queued_s = walker.planned_frames / rate - k / rate
        added = False
        if (not any(s.start_s >= k / rate for s in walker.planned_steps[-1:]) if as_drive else queued_s < LOOKAHEAD_S):
            command = VelocityCommand(*COMMANDS[int(k / rate / 6.0) % len(COMMANDS)])
            p0 = clock()
            step = planner.next_step(command, walker.next_swing_side)
            plan_times.append(clock() - p0)
            walker.append_footstep(step.foothold, step.length_m, spread=spread)
            added = True
        elif spread:
            walker.work()
        frame = walker.next_frame()
        frames.append(clock() - t0 if not keep else frame)
        appended.append(added)
        k += 1
        if frame is None:
            break
    if keep:
        frames = [f for f in frames if f is not None]
    return rate, frames, plan_times, appended


def main(argv=None) -> int:
    from gaitbot.app.options import load_robot

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", help="robot config (default op3; --compare: op3 and bioloid)")
    p.add_argument("--seconds", type=float, default=30.0)
    p.add_argument("--spread", action="store_true", help="spread each replan over the next frames (gaitbot drive)")
    p.add_argument("--cpu", action="store_true", help="CPU time (time.process_time) instead of the wall clock")
    p.add_argument("--compare", action="store_true", help="print how far the spread walk's frames are from the at-once "
                   "walk's (no timing)")
    p.add_argument("--markdown", action="store_true", help="--compare as the docs' figure block")
    args = p.parse_args(argv)
    clock = time.process_time if args.cpu else time.perf_counter
    if args.compare or args.markdown:
        lines = []
        for robot in ([args.robot] if args.robot else ["op3", "bioloid"]):
            config = load_robot(robot)
            _, at_once, _, _ = walk(config, args.seconds, False, clock, keep=True, as_drive=True)
            _, spread, _, _ = walk(config, args.seconds, True, clock, keep=True, as_drive=True)
            q = np.abs(np.array([f[1] for f in at_once]) - np.array([f[1] for f in spread])).max()
            root = np.abs(np.array([f[3] for f in at_once]) - np.array([f[3] for f in spread])).max()
            lines.append(f"{robot}, {len(at_once)} frames: the spread replan's angles within {math.degrees(q):.3f} deg "
                         f"of the at-once replan's, the root within {1e3 * root:.3f} mm")
        text = "\n".join(lines)
        print(f"<!-- figure spread-vs-at-once -->\n```text\n{text}\n```\n<!-- /figure -->" if args.markdown else text)
        return 0
    config = load_robot(args.robot or "op3")
    rate, frames, plan_times, appended = walk(config, args.seconds, args.spread, clock)
    f = 1e3 * np.array(frames)
    a = np.array(appended)
    how = "each replan spread over the frames after it" if args.spread else "each replan at once"
    print(f"{args.robot or 'op3'}: {len(f)} frames ({len(f) / rate:.0f} s), {a.sum()} steps appended while walking ({how}; "
          f"{'CPU' if args.cpu else 'wall'} time)")
    for label, x in (("every frame", f), ("frames without an append", f[~a]), ("frames that appended a step", f[a])):
        print(f"  {label}: p50 {np.percentile(x, 50):.2f} ms, p99 {np.percentile(x, 99):.2f} ms, max {x.max():.2f} ms")
    q = 1e3 * np.array(plan_times)
    print(f"  planning one step: p50 {np.percentile(q, 50):.2f} ms, max {q.max():.2f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
