"""Measure and verify the terrain step envelope of the shipped robots (or given robot configs).

    python tools/terrain_envelope.py                       # verify each robot's [terrain] table, print it
    python tools/terrain_envelope.py --measure             # bisect rise, drop and gap with the generator
    python tools/terrain_envelope.py --random 40 --seed 1  # also walk 40 random courses inside the envelope
    python tools/terrain_envelope.py --markdown            # the configs' envelopes as docs/terrain.md's table

A value "walks" when the planner finds footholds and the generated walk passes ``gaitbot check``'s
limits (positions, velocities, accelerations) on every course of its family:

- rise r: three stairs up of rise r, then a landing, at goings from the shortest (a foot plus its
  margins) to twice that, and a single kerb of r;
- drop r: the same going down (from a landing into a pit), and a single drop;
- gap w: a ditch w wide (and 5 cm deep) between level ground, and gaps w (1 - f)^2 before a step
  of f times the largest rise and drop, f = 1/2 and 1/5 (the envelope's curve, envelope.py).

``--measure`` bisects each value on a 2.5 mm grid, with the others at 0, then states the envelope
one grid step below what it found (a margin for courses between the measured ones) and verifies
that together; the printout ends with the ``[terrain]`` table to put in the robot config.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.check.trajectory import check_trajectory  # noqa: E402
from gaitbot.gait.walk_segments import GaitGenerationError  # noqa: E402
from gaitbot.gait.terrain.envelope import StepEnvelope  # noqa: E402
from gaitbot.gait.terrain.footholds import CourseError  # noqa: E402
from gaitbot.gait.terrain.model import Terrain, Tread  # noqa: E402
from gaitbot.gait.terrain.walk import plan_terrain_walk  # noqa: E402
from gaitbot.gait.walker import make_context  # noqa: E402
from gaitbot.robot.config import load_robot_config, shipped_config_names, resolve_config  # noqa: E402
from gaitbot.robot.walk_settings import leg_geometry, walk_settings  # noqa: E402
from gaitbot.robot.walk_settings import GaitSource, terrain_settings  # noqa: E402
from gaitbot.gait.terrain.course_file import Course  # noqa: E402

GRID = 0.0025
START = 0.30  # where the first tread begins (the walk starts at 0 on flat ground)


def stairs(rise: float, going: float, n: int = 3, landing: float = 0.4) -> Course:
    """n stairs of ``going``, each ``rise`` higher (negative: lower) than the last, then a landing."""
    treads = tuple(Tread(round(START + i * going, 6), round(going, 6), round(rise * (i + 1), 6)) for i in range(n))
    treads += (Tread(round(START + n * going, 6), landing, round(rise * n, 6)),)
    return Course(f"stairs {rise * 1000:+.1f} mm x {going * 1000:.0f} mm", Terrain(treads), 0.0,
                  round(START + n * going + 0.2, 6))


def kerb(rise: float) -> Course:
    return Course(f"kerb {rise * 1000:+.1f} mm", Terrain((Tread(START, 0.6, round(rise, 6)),)), 0.0, START + 0.4)


def gap(width: float, rise: float = 0.0) -> Course:
    """A ditch ``width`` wide and 5 cm deep (none if 0); past it the ground at ``rise``."""
    treads = (Tread(START, round(width, 6), -0.05),) if width > 1e-6 else ()
    if rise:
        treads += (Tread(round(START + width, 6), 0.6, round(rise, 6)),)
    return Course(f"gap {width * 1000:.1f} mm, then {rise * 1000:+.1f} mm", Terrain(treads), 0.0,
                  round(START + width + 0.35, 6))


class Robot:
    def __init__(self, name: str) -> None:
        self.config = load_robot_config(resolve_config(name))
        self.name = self.config.name
        self.geometry = leg_geometry(self.config)
        self.source = GaitSource(self.geometry, walk_settings(self.config), self.config.gait.max_step_m, self.config)
        self.ctx = make_context(self.geometry, self.source.settings)
        self.shortest = self.geometry.foot + 0.02

    def envelope(self, rise: float, drop: float, gap_: float) -> StepEnvelope:
        return StepEnvelope.for_foot(self.geometry.foot, rise, drop, gap_, self.name)

    def walks(self, course: Course, envelope: StepEnvelope) -> str | None:
        """None if the course walks within the limits, else why not (one line)."""
        settings = replace(terrain_settings(self.source, course), envelope=envelope)
        try:
            walk = plan_terrain_walk(self.ctx, course.terrain, course.start_m, course.end_m, settings,
                                     self.source.max_step_m)
        except (CourseError, GaitGenerationError) as exc:
            return f"{course.path}: {exc}"
        report = check_trajectory(self.config, walk.trajectory.t_s, np.degrees(walk.trajectory.angles_rad))
        return None if report.ok else f"{course.path}: {report.first_error}"


def families(robot: Robot, env: StepEnvelope) -> dict[str, list[Course]]:
    s = robot.shortest
    goings = (s, s + 0.01, s + 0.03, 1.5 * s, 2.0 * s)
    return {
        "rise": [stairs(env.max_rise, g) for g in goings] + [kerb(env.max_rise)],
        "drop": [stairs(-env.max_drop, g) for g in goings] + [kerb(-env.max_drop)],
        "gap": [gap(env.max_gap), gap(env.max_gap / 4, env.max_rise / 2), gap(env.max_gap / 4, -env.max_drop / 2),
                gap(0.64 * env.max_gap, env.max_rise / 5), gap(0.64 * env.max_gap, -env.max_drop / 5)],
    }


def first_failure(robot: Robot, courses, env: StepEnvelope) -> str | None:
    for course in courses:
        why = robot.walks(course, env)
        if why:
            return why
    return None


def bisect(robot: Robot, family: str, hi: float) -> float:
    """Largest value on the GRID (0 to hi) whose family walks, the others at 0."""
    lo_ok, hi_bad = 0, int(round(hi / GRID))
    while hi_bad - lo_ok > 1:
        mid = (lo_ok + hi_bad) // 2
        value = mid * GRID
        env = robot.envelope(*(value if family == f else 0.0 for f in ("rise", "drop", "gap")))
        courses = families(robot, env)[family]
        if family == "gap":
            courses = courses[:1]
        if first_failure(robot, courses, env) is None:
            lo_ok = mid
        else:
            hi_bad = mid
    return lo_ok * GRID


def random_courses(robot: Robot, env: StepEnvelope, count: int, seed: int) -> list[Course]:
    """Stairs of several rises and goings inside the envelope: 2 to 5 treads, each rise or drop up to the
    largest, each going from the shortest to twice that, now and then a gap of up to half the widest."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        x, h, treads = START, 0.0, []
        for _ in range(int(rng.integers(2, 6))):
            if rng.random() < 0.2 and env.max_gap > 0.01:  # a ditch 5 cm deep
                width = round(float(rng.uniform(0.005, 0.5 * env.max_gap)), 4)
                treads.append(Tread(x, width, round(h - 0.05, 4)))
                x = round(x + width, 4)
                dh = 0.0
            else:
                dh = float(rng.uniform(-env.max_drop, env.max_rise))
            going = round(float(rng.uniform(robot.shortest, 2 * robot.shortest)), 4)
            h = round(h + dh, 4)
            treads.append(Tread(x, going, h))
            x = round(x + going, 4)
        treads.append(Tread(x, 0.4, round(h + float(rng.uniform(-env.max_drop, env.max_rise)), 4)))
        out.append(Course(f"random course {i + 1}", Terrain(tuple(treads)), 0.0, round(x + 0.25, 4)))
    return out


def terrain_robots() -> list[str]:
    """The shipped robots the terrain walker drives: those with a [terrain] table (the pitch-only ones; a
    robot whose legs roll walks the balanced gait, on the flat only)."""
    return [n for n in shipped_config_names() if load_robot_config(resolve_config(n)).terrain is not None]


def markdown(names) -> str:
    """The envelope table of docs/terrain.md: each robot's configured [terrain] values (what --measure found, one
    grid step less, and what the verification walks), without walking anything."""
    lines = ["| robot | leg | foot | max rise | max drop | min going | max ditch |", "|---|---|---|---|---|---|---|"]
    for name in names:
        robot = Robot(name)
        reach, leg = robot.config.terrain, robot.geometry.leg_length
        lines.append(f"| {robot.name} | {leg * 1000:.0f} mm | {robot.geometry.foot * 1000:.0f} mm | "
                     f"{reach.max_rise_m * 1000:.1f} mm ({reach.max_rise_m / leg:.2f} leg) | "
                     f"{reach.max_drop_m * 1000:.1f} mm ({reach.max_drop_m / leg:.2f} leg) | "
                     f"{robot.shortest * 1000:.0f} mm ({robot.shortest / leg:.2f} leg) | {reach.max_gap_m * 1000:.1f} mm |")
    return "<!-- figure terrain-envelope -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", action="append", help="robot config name or path (default: every shipped one with a [terrain] table)")
    parser.add_argument("--measure", action="store_true", help="bisect the envelope instead of verifying the config's")
    parser.add_argument("--random", type=int, default=0, help="also walk this many random courses inside it")
    parser.add_argument("--seed", type=int, default=1, help="seed of the random courses")
    parser.add_argument("--markdown", action="store_true", help="print the configured envelopes as the docs' table")
    args = parser.parse_args()
    if args.markdown:
        print(markdown(args.robot or sorted(terrain_robots(), key=lambda n: n != "xl430-biped")))
        return 0
    status = 0
    for name in args.robot or terrain_robots():
        robot = Robot(name)
        t0 = time.perf_counter()
        if args.measure:
            leg = robot.geometry.leg_length
            with progress(f"{robot.name}: bisecting rise, drop, gap", total=3, unit="value") as bar:
                found = {}
                for family in ("rise", "drop", "gap"):
                    found[family] = bisect(robot, family, 0.4 * leg)
                    bar.update(1)
            env = robot.envelope(*(max(0.0, found[f] - GRID) for f in ("rise", "drop", "gap")))
            print(f"{robot.name}: walks rise {found['rise'] * 1000:.1f} mm, drop {found['drop'] * 1000:.1f} mm, "
                  f"gap {found['gap'] * 1000:.1f} mm (each alone, {time.perf_counter() - t0:.0f} s)")
        else:
            reach = robot.config.terrain
            if reach is None:
                print(f"{robot.name}: no [terrain] table (run with --measure)")
                status = 1
                continue
            env = robot.envelope(reach.max_rise_m, reach.max_drop_m, reach.max_gap_m)
        courses = [c for family in families(robot, env).values() for c in family]
        courses += random_courses(robot, env, args.random, args.seed)
        failures = []
        with progress(f"{robot.name}: walking courses", total=len(courses), unit="course") as bar:
            for course in courses:
                why = robot.walks(course, env)
                if why:
                    failures.append(why)
                bar.update(1)
        leg = robot.geometry.leg_length
        print(f"{robot.name} (leg {leg * 1000:.0f} mm, foot {robot.geometry.foot * 1000:.0f} mm): "
              f"max rise {env.max_rise * 1000:.1f} mm ({env.max_rise / leg:.2f} leg), "
              f"max drop {env.max_drop * 1000:.1f} mm ({env.max_drop / leg:.2f} leg), "
              f"min going {robot.shortest * 1000:.0f} mm ({robot.shortest / leg:.2f} leg), "
              f"max gap (ditch) {env.max_gap * 1000:.1f} mm; "
              f"{len(courses) - len(failures)}/{len(courses)} courses walk ({time.perf_counter() - t0:.0f} s)")
        for why in failures:
            print(f"  FAILS {why}")
            status = 1
        if args.measure:
            print(f"  [terrain]\n  max_rise_m = {env.max_rise:.4f}\n  max_drop_m = {env.max_drop:.4f}\n"
                  f"  max_gap_m = {env.max_gap:.4f}")
    return status


if __name__ == "__main__":
    sys.exit(main())
