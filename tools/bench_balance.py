"""Per-frame costs of the balanced walk (docs/benchmarks.md, "The balanced walk"). Run: python tools/bench_balance.py

- online: BalancedWalker.next_frame over a 30-step op3 walk queued ahead (both preview stages, pelvis
  placement, IK, sag feedforward): p50 / p99 / max over every frame (the rise from straight legs runs the
  first preview stage one horizon ahead, a few frames at a time); the largest frame is named;
- append: BalancedWalker.append_step while walking (one step appended every step, 200 steps);
- offline: generate_balanced_walk frames per second for a 10 m walk (swing-shape table and Riccati gains
  warm, as they are cached per robot and cycle; the cold first call is reported apart);
- simulation: ``gaitbot walk --sim --robot op3 --distance 2`` (the whole command in-process: planning,
  preflight, model, every packet through the SDK) and the physics alone, against the simulated time.
"""

from __future__ import annotations

import contextlib
import io
import os
import platform
import time

import numpy as np

from gaitbot.gait.balance.walker import BalancedWalker, generate_balanced_walk
from gaitbot.robot.balanced_walk import balanced_gait_settings, balanced_walker
from gaitbot.robot.config import load_robot_config, resolve_config


def timed(call):
    """(wall ms, CPU ms of this thread) of one call: the wall time includes being preempted on a shared
    machine, the CPU time is what the code itself costs."""
    wall, cpu = time.perf_counter(), time.thread_time()
    result = call()
    return result, (time.perf_counter() - wall) * 1e3, (time.thread_time() - cpu) * 1e3


def percentiles(label: str, wall, cpu, what: str) -> None:
    wall, cpu = np.array(wall), np.array(cpu)
    print(f"{label}: wall p50 {np.percentile(wall, 50):.3f} ms, p99 {np.percentile(wall, 99):.3f} ms, max "
          f"{wall.max():.3f} ms; CPU p50 {np.percentile(cpu, 50):.3f} ms, p99 {np.percentile(cpu, 99):.3f} ms, max "
          f"{cpu.max():.3f} ms over {len(wall)} {what}")


def online(config) -> None:
    walker = balanced_walker(config)
    for _ in range(30):
        walker.append_step(0.05)
    wall, cpu = [], []
    while True:
        frame, w, c = timed(walker.next_frame)
        if frame is None:
            break
        wall.append(w)
        cpu.append(c)
    percentiles("online next_frame", wall, cpu, "frames")


def append(config) -> None:
    walker: BalancedWalker = balanced_walker(config)
    for _ in range(3):
        walker.append_step(0.05)
    wall, cpu, frames = [], [], 0
    while len(wall) < 200:
        walker.next_frame()
        frames += 1
        if frames % walker.timing.step_frames == 0:
            _, w, c = timed(lambda: walker.append_step(0.05))
            wall.append(w)
            cpu.append(c)
    percentiles("append_step while walking", wall, cpu, "appends")


def offline(config) -> None:
    gait = balanced_gait_settings(config)
    t = time.perf_counter()
    generate_balanced_walk(config.body, [0.05] * 4, gait, config.balance)
    cold = time.perf_counter() - t
    best = 0.0
    for _ in range(3):
        t = time.perf_counter()
        walk = generate_balanced_walk(config.body, [0.05] * 200, gait, config.balance)
        best = max(best, len(walk.t_s) / (time.perf_counter() - t))
    print(f"offline generate_balanced_walk: {len(walk.t_s)} frames, best of 3 {best:,.0f} frames/s "
          f"(first call of the process with cold caches: {cold:.2f} s for a 4-step walk)")


def simulation() -> None:
    from gaitbot.app.cli import main
    from gaitbot.robot.balanced_walk import plan_balanced
    from gaitbot.sim.physics import SimRobot

    t = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()):
        main(["walk", "--sim", "--json", "--robot", "op3", "--distance", "2"])
    whole = time.perf_counter() - t
    import json

    simulated = json.loads(out.getvalue())["simulated_s"]
    config = load_robot_config(resolve_config("op3"))
    walk = plan_balanced(config, [0.05] * 40).walk
    robot = SimRobot(config, 60.0, support="free")
    for i in range(len(robot.joint_names)):
        robot.set_torque(i, True)
    t = time.perf_counter()
    for k, q in enumerate(walk.goals_rad):
        for i, a in enumerate(q):
            robot.set_goal(i, float(a))
        robot.advance_to((k + 1) / 60.0)
    physics = time.perf_counter() - t
    print(f"simulation: gaitbot walk --sim --robot op3 --distance 2: {simulated:.1f} s simulated in {whole:.2f} s "
          f"({simulated / whole:.0f}x real time); the physics alone {len(walk.t_s) / 60:.1f} s in {physics:.2f} s "
          f"({len(walk.t_s) / 60 / physics:.0f}x)")


def main() -> None:
    config = load_robot_config(resolve_config("op3"))
    online(config)
    append(config)
    offline(config)
    simulation()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}, "
          f"python {platform.python_version()}, numpy {np.__version__}")


if __name__ == "__main__":
    main()
