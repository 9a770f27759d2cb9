"""Benchmark of the live drive's 60 Hz frame: the work of one frame (input poll, replanning, the walker, the
check, the ticks), the walker's next_frame alone, and the time from a command to the step that carries it.

    python tools/bench_drive.py --robot op3 --minutes 2 --seed 1

Random commands (seeded, changing every 2-5 s, anywhere within the robot's [steer] limits, stops included)
are played on the drive's own clock; CPU time per call (time.process_time), one thread.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from gaitbot.app.options import load_robot  # noqa: E402
from gaitbot.drive.frames import DriveFrames, command_limits  # noqa: E402
from gaitbot.gait.steer.command import TimedCommand, VelocityCommand  # noqa: E402
from gaitbot.inputs.scripted import ScriptedSource  # noqa: E402
from gaitbot.robot.steered_walk import footstep_planner  # noqa: E402

STILL_SHARE = 0.15


def random_commands(config, minutes: float, seed: int) -> list[TimedCommand]:
    """Commands changing every 2-5 s, uniform within the robot's limits on each axis, some of them stops."""
    rng = np.random.default_rng(seed)
    top, bottom = command_limits(config.steer, footstep_planner(config).step_s)
    commands, t = [], 0.0
    while t < minutes * 60:
        if rng.random() < STILL_SHARE:
            command = VelocityCommand()
        else:
            command = VelocityCommand(*(float(rng.uniform(getattr(bottom, a), getattr(top, a)))
                                        for a in ("vx_m_s", "vy_m_s", "wz_deg_s")))
        commands.append(TimedCommand(round(t, 3), command))
        t += float(rng.uniform(2.0, 5.0))
    commands.append(TimedCommand(round(minutes * 60, 3), stop=True))
    return commands


def measure(robot: str, minutes: float, seed: int) -> dict:
    config = load_robot(robot)
    frames = DriveFrames(config, ScriptedSource(random_commands(config, minutes, seed)), say=lambda s: None)
    walker_s: list[float] = []

    def timed_walker(walker):
        inner = walker.next_frame

        def next_frame():
            start = time.process_time()
            out = inner()
            walker_s.append(time.process_time() - start)
            return out
        walker.next_frame = next_frame

    frame_s = []
    timed_walker(frames._walker)
    walker_id = id(frames._walker)
    while True:
        start = time.process_time()
        try:
            next(frames)
        except StopIteration:
            break
        frame_s.append(time.process_time() - start)
        if id(frames._walker) != walker_id:
            timed_walker(frames._walker)
            walker_id = id(frames._walker)
    ms = 1e3
    f, w, lat = np.array(frame_s) * ms, np.array(walker_s) * ms, np.array(frames.log.latencies_s)
    return {"robot": robot, "frames": len(f), "frame_p50_ms": np.percentile(f, 50), "frame_p99_ms": np.percentile(f, 99),
            "frame_max_ms": f.max(), "next_frame_p99_ms": np.percentile(w, 99), "latency_median_s": np.median(lat),
            "latency_max_s": lat.max(), "steps": frames.log.steps}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config (repeatable; default op3 and bioloid)")
    parser.add_argument("--minutes", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    print("| robot | frames | frame work p50 ms | p99 ms | max ms | next_frame p99 ms | command to its step, "
          "median s | max s |")
    print("|---|---|---|---|---|---|---|---|")
    for robot in args.robot or ["op3", "bioloid"]:
        r = measure(robot, args.minutes, args.seed)
        print(f"| {r['robot']} | {r['frames']} | {r['frame_p50_ms']:.3f} | {r['frame_p99_ms']:.3f} | "
              f"{r['frame_max_ms']:.2f} | {r['next_frame_p99_ms']:.3f} | {r['latency_median_s']:.2f} | "
              f"{r['latency_max_s']:.2f} |")


if __name__ == "__main__":
    main()
