"""Benchmark of the terrain walker (Zhang 2008): a 10-stair course, and the grid search on the examples.

    python tools/bench_terrain.py                    # both parts
    python tools/bench_terrain.py stairs [--rise 0.035 --going 0.16 --repeat 3]
    python tools/bench_terrain.py search             # every example course of every shipped robot
    python tools/bench_terrain.py search --markdown  # the search's figures for docs/terrain.md (tools/figures.py)

stairs: foothold planning time, whole-walk generation time (footholds, grid searches, segments,
every frame) and frames per second, and the grid search's cells scored against the 625 of a
full search per MDS point, for ten stairs up (default robot; rise and going as given).

search: for every MDS point of every example course (config/terrain/ for the default robot,
config/terrain/<robot>/ for the others): the cost of Zhang's two-level search, of simply taking
the middle of the region, and of a 25 x 25 brute force of the same region, with the cells each
scored. Per course the sums and the worst ratio of two-level to brute force are printed.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.gait.terrain.footholds import plan_footholds  # noqa: E402
from gaitbot.gait.terrain.model import Terrain, Tread  # noqa: E402
from gaitbot.gait.terrain.walk import plan_terrain_walk, terrain_limits  # noqa: E402
from gaitbot.gait.walker import make_context  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names  # noqa: E402
from gaitbot.robot.walk_settings import leg_geometry, walk_settings  # noqa: E402
from gaitbot.robot.walk_settings import GaitSource, terrain_settings  # noqa: E402
from gaitbot.gait.terrain.course_file import Course, load_course  # noqa: E402

DEFAULT_ROBOT = "xl430-biped"


class Robot:
    def __init__(self, name: str) -> None:
        self.config = load_robot_config(resolve_config(name))
        self.geometry = leg_geometry(self.config)
        self.source = GaitSource(self.geometry, walk_settings(self.config), self.config.gait.max_step_m, self.config)
        self.ctx = make_context(self.geometry, self.source.settings)

    def walk(self, course: Course):
        settings = terrain_settings(self.source, course)
        return plan_terrain_walk(self.ctx, course.terrain, course.start_m, course.end_m, settings,
                                 self.source.max_step_m), settings


def ten_stairs(rise: float, going: float, n: int = 10) -> Course:
    treads = tuple(Tread(round(0.35 + i * going, 6), going, round(rise * (i + 1), 6)) for i in range(n))
    treads += (Tread(round(0.35 + n * going, 6), 0.5, round(rise * n, 6)),)
    return Course(f"{n} stairs", Terrain(treads), 0.0, round(0.35 + n * going + 0.3, 6))


def bench_stairs(rise: float, going: float, repeat: int) -> None:
    robot = Robot(DEFAULT_ROBOT)
    course = ten_stairs(rise, going)
    settings = terrain_settings(robot.source, course)
    limits = terrain_limits(robot.ctx, settings, robot.source.max_step_m)
    plan_times, gen_times = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        holds = plan_footholds(course.terrain, course.start_m, course.end_m, limits)
        plan_times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        walk, _ = robot.walk(course)
        gen_times.append(time.perf_counter() - t0)
    n_frames = len(walk.trajectory)
    reports = walk.search_reports
    print(f"10 stairs up, rise {rise * 1000:.1f} mm, going {going * 1000:.0f} mm, {DEFAULT_ROBOT}:")
    print(f"  plan footholds: {min(plan_times) * 1000:.1f} ms ({len(holds)} footholds; best of {repeat})")
    print(f"  generate walk: {min(gen_times) * 1000:.0f} ms for {n_frames} frames ({n_frames / min(gen_times):.0f} "
          f"frames/s, {walk.trajectory.t_s[-1]:.1f} s of walking), {len(walk.steps)} steps, "
          f"{sum(s.method == 'terrain' for s in walk.steps)} on terrain")
    print(f"  grid search: {len(reports)} MDS points, {sum(r.evaluated for r in reports)} cells scored + "
          f"{sum(r.pruned for r in reports)} skipped as unreachable, against {sum(r.full_grid for r in reports)} "
          f"for full 625-cell searches")


def example_courses():
    for name in shipped_config_names():
        where = ROOT / "config" / "terrain" / ("" if name == DEFAULT_ROBOT else name)
        for example in ("kerb", "stairs", "ditch"):
            path = where / f"{example}.toml"
            if path.is_file():
                yield name, path


def search_rows():
    """Per example course: (robot, course, MDS points, two-level cost, 25x25 cost, worst ratio, cells scored,
    cells of full 5x5x5x5 searches, 25x25 cells scored, middle-of-region cost, two-level cost at the same points,
    middles out of reach); and every point's ratio of two-level to brute force."""
    robots: dict[str, Robot] = {}
    rows, all_ratios = [], []
    courses = list(example_courses())
    with progress("grid search against 25 x 25", total=len(courses), unit="course") as bar:
        for name, path in courses:
            robot = robots.setdefault(name, Robot(name))
            walk, _ = robot.walk(load_course(path))
            fast_sum = full_sum = middle_sum = paired_sum = 0.0
            fast_cells = full_cells = middle_out = 0
            worst = 1.0
            for problem in walk.search_problems:
                fast = problem.search()
                full = problem.brute_force(25)
                fast_sum += fast.cost
                full_sum += full.cost
                if np.isfinite(fast.centre_cost):
                    middle_sum += fast.centre_cost
                    paired_sum += fast.cost
                else:
                    middle_out += 1
                fast_cells += fast.evaluated
                full_cells += full.evaluated
                ratio = fast.cost / full.cost if full.cost > 0 else 1.0
                worst = max(worst, ratio)
                all_ratios.append(ratio)
            count = len(walk.search_problems)
            rows.append((name, path.stem, count, fast_sum, full_sum, worst, fast_cells, 625 * count, full_cells,
                         middle_sum, paired_sum, middle_out))
            bar.update(1)
    return rows, np.array(all_ratios)


def bench_search(as_markdown: bool = False) -> None:
    rows, ratios = search_rows()
    if as_markdown:
        print(search_markdown(rows, ratios))
        return
    print("grid search on the example courses (costs: weighted squared joint accelerations, (rad/s^2)^2 s, summed over")
    print("the MDS points; 'middle': the middle of each region where the legs can take it, against the two-level")
    print("search at the same points):")
    print(f"  {'robot':14s} {'course':7s} {'MDS':>4s} {'two-level':>10s} {'25x25':>10s} {'worst ratio':>11s} "
          f"{'cells scored':>14s} {'25x25 cells':>11s}   middle vs two-level")
    for name, course, count, fast, full, worst, cells, of, full_cells, middle, paired, out in rows:
        middle_text = f"{middle:.1f} vs {paired:.1f}" + (f" ({out} middles out of reach)" if out else "")
        print(f"  {name:14s} {course:7s} {count:4d} {fast:10.1f} {full:10.1f} {worst:11.3f} "
              f"{cells:5d} of {of:5d} {full_cells:11d}   {middle_text}")
    print(f"  all {len(ratios)} MDS points: two-level / 25x25 median {np.median(ratios):.4f}, worst {ratios.max():.4f}, "
          f"{np.mean(ratios <= 1.05) * 100:.0f}% within 5%")


def search_markdown(rows, ratios) -> str:
    table = ["| robot, course | MDS points | two-level | 25 x 25 | worst ratio | cells scored (two-level / 25 x 25) | "
             "middle of region vs two-level |", "|---|---|---|---|---|---|---|"]
    for name, course, count, fast, full, worst, cells, of, full_cells, middle, paired, out in rows:
        reach = f" ({out} middle{'s' if out != 1 else ''} out of reach)" if out else ""
        table.append(f"| {name.split('-')[0]} {course} | {count} | {fast:.1f} | {full:.1f} | {worst:.3f} | "
                     f"{cells} / {full_cells} of {of} | {middle:.1f} vs {paired:.1f}{reach} |")
    outs = sum(r[11] for r in rows)
    factors = [r[9] / r[10] for r in rows if r[10] > 0]
    summary = (f"Over all {len(ratios)} points the two-level search's cost is {np.median(ratios):.3f} times the brute "
               f"force's at the median and {ratios.max():.3f} at worst ({np.mean(ratios <= 1.05) * 100:.0f}% within 5%), "
               f"scoring about {sum(r[6] for r in rows) / sum(r[8] for r in rows):.2f} of its cells; the middle of the "
               f"region is out of the legs' reach at {outs} of them and costs {min(factors):.0f} to "
               f"{max(factors):.0f} times more elsewhere (summed per course).")
    return (f"<!-- figure terrain-search -->\n" + "\n".join(table) + "\n<!-- /figure -->\n"
            f"<!-- figure terrain-search-summary -->\n{summary}\n<!-- /figure -->")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("parts", nargs="*", default=["stairs", "search"], help="stairs, search")
    parser.add_argument("--rise", type=float, default=0.035)
    parser.add_argument("--going", type=float, default=0.16)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--markdown", action="store_true", help="search: print the docs' figures (tools/figures.py)")
    args = parser.parse_args(argv)
    if args.markdown:
        bench_search(as_markdown=True)
        return 0
    print(f"machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}")
    for part in args.parts:
        if part == "stairs":
            bench_stairs(args.rise, args.going, args.repeat)
        elif part == "search":
            bench_search()
        else:
            parser.error(f"unknown part {part!r} (stairs, search)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
