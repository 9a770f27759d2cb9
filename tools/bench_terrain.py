"""Benchmark of the terrain walker (seed 003): plan and generate a 10-stair course.

    python tools/bench_terrain.py [--rise 0.02] [--going 0.16] [--repeat 3]

Prints: foothold planning time, whole-walk generation time (footholds, grid searches, segments,
every frame), frames per second of generation, the grid search's cells scored against the 625 of a
full search per MDS point, and for a few MDS points the two-level cost against a 25 x 25
brute-force search of the same region and against the middle of the region.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gaitbot.gait.terrain.footholds import plan_footholds  # noqa: E402
from gaitbot.gait.terrain.model import Terrain, Tread  # noqa: E402
from gaitbot.gait.terrain.walk import plan_terrain_walk, terrain_limits  # noqa: E402
from gaitbot.gait.walker import make_context  # noqa: E402
from gaitbot.robot.config import default_config_path, load_robot_config  # noqa: E402
from gaitbot.robot.gait_setup import leg_geometry, walk_settings  # noqa: E402
from gaitbot.session import GaitSource, terrain_settings  # noqa: E402
from gaitbot.terrain_file import Course  # noqa: E402


def stairs(rise: float, going: float, n: int = 10) -> Course:
    treads = tuple(Tread(round(0.35 + i * going, 6), going, round(rise * (i + 1), 6)) for i in range(n))
    treads += (Tread(round(0.35 + n * going, 6), 0.5, round(rise * n, 6)),)
    return Course("10 stairs", Terrain(treads), 0.0, round(0.35 + n * going + 0.3, 6))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rise", type=float, default=0.02)
    parser.add_argument("--going", type=float, default=0.16)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    robot = load_robot_config(default_config_path())
    geometry = leg_geometry(robot)
    source = GaitSource(geometry, walk_settings(robot), robot.gait.max_step_m, robot)
    course = stairs(args.rise, args.going)
    settings = terrain_settings(source, course)
    ctx = make_context(geometry, source.settings)
    limits = terrain_limits(ctx, settings, source.max_step_m)
    plan_times, gen_times = [], []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        holds = plan_footholds(course.terrain, course.start_m, course.end_m, limits)
        plan_times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        walk = plan_terrain_walk(ctx, course.terrain, course.start_m, course.end_m, settings, source.max_step_m)
        gen_times.append(time.perf_counter() - t0)
    n_frames = len(walk.trajectory)
    reports = walk.search_reports
    print(f"machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}")
    print(f"course: 10 stairs, rise {args.rise * 1000:.0f} mm, going {args.going * 1000:.0f} mm, robot {robot.name}")
    print(f"plan footholds: {min(plan_times) * 1000:.1f} ms ({len(holds)} footholds; best of {args.repeat})")
    print(f"generate walk: {min(gen_times) * 1000:.0f} ms for {n_frames} frames ({n_frames / min(gen_times):.0f} "
          f"frames/s), {len(walk.steps)} steps, {sum(s.method == 'terrain' for s in walk.steps)} on terrain")
    print(f"grid search: {len(reports)} MDS points, {sum(r.evaluated for r in reports)} cells scored + "
          f"{sum(r.pruned for r in reports)} skipped as unreachable, against {sum(r.full_grid for r in reports)} "
          f"for full 625-cell searches")
    for i, problem in enumerate(walk.search_problems[:4], start=1):
        t0 = time.perf_counter()
        fast = problem.search()
        t_fast = time.perf_counter() - t0
        t0 = time.perf_counter()
        full = problem.brute_force(25)
        t_full = time.perf_counter() - t0
        centre = f"{fast.centre_cost:.4g}" if np.isfinite(fast.centre_cost) else "unreachable"
        print(f"MDS {i}: two-level cost {fast.cost:.4g} ({fast.evaluated} scored, {t_fast * 1000:.1f} ms), "
              f"brute force {full.cost:.4g} ({full.evaluated} scored, {t_full * 1000:.0f} ms), "
              f"ratio {fast.cost / full.cost:.4f}, middle of region {centre}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
