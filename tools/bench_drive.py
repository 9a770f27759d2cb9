"""Benchmark of the live drive's 60 Hz frame: the work of one frame (input poll, replanning, the walker, the
check, the ticks), the walker's next_frame alone, and the time from a command to the step that carries it.

    python tools/bench_drive.py --robot op3 --minutes 2 --seed 1
    python tools/bench_drive.py --latency --markdown    # the latency alone, as docs/benchmarks.md's figure

Random commands (seeded, changing every 2-5 s, anywhere within the robot's [steer] limits, stops included)
are played on the drive's own clock; CPU time per call (time.process_time), one thread. The load average
is printed beside the figures (the machine's other work inflates the tail). The latency (from a new command
to the start of the first step planned from it) is on the drive's own clock: the same on any machine.
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
            "frame_max_ms": f.max(), "next_frame_p50_ms": np.percentile(w, 50),
            "next_frame_p99_ms": np.percentile(w, 99), "latency_median_s": np.median(lat),
            "latency_p90_s": np.percentile(lat, 90), "latency_max_s": lat.max(), "latencies": len(lat),
            "steps": frames.log.steps, "step_s": footstep_planner(config).step_s}


def latency_table(rows: list[dict]) -> str:
    lines = ["| robot | commands changed while walking | step s | command to its step, median s | p90 s | max s |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['robot']} | {r['latencies']} | {r['step_s']:.3f} | {r['latency_median_s']:.2f} | "
              f"{r['latency_p90_s']:.2f} | {r['latency_max_s']:.2f} |" for r in rows]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config (repeatable; default op3 and bioloid)")
    parser.add_argument("--minutes", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--latency", action="store_true", help="print only the latency (the same on any machine)")
    parser.add_argument("--markdown", action="store_true", help="print the latency as the docs' figure block")
    args = parser.parse_args()
    load_before = os.getloadavg()
    rows = [measure(robot, args.minutes, args.seed) for robot in args.robot or ["op3", "bioloid"]]
    if args.latency or args.markdown:
        table = latency_table(rows)
        print(f"<!-- figure drive-latency -->\n{table}\n<!-- /figure -->" if args.markdown else table)
        return
    print(f"load average {' '.join(f'{v:.2f}' for v in load_before)} (1, 5, 15 min) before the run")
    print("| robot | frames | frame work p50 ms | p99 ms | max ms | next_frame p50 ms | p99 ms | command to its step, "
          "median s | max s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['robot']} | {r['frames']} | {r['frame_p50_ms']:.3f} | {r['frame_p99_ms']:.3f} | "
              f"{r['frame_max_ms']:.2f} | {r['next_frame_p50_ms']:.3f} | {r['next_frame_p99_ms']:.3f} | "
              f"{r['latency_median_s']:.2f} | {r['latency_max_s']:.2f} |")
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())} after the run")


if __name__ == "__main__":
    main()
