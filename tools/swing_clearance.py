"""Swing clearance of every swing of the planar walks: flat and every example terrain course, every pitch-only robot.

    python tools/swing_clearance.py              # the table
    python tools/swing_clearance.py --markdown   # the docs' figure (docs/gait.md, docs/terrain.md)

Measured on the frames by gaitbot/gait/swing_clearance.py (one rule for flat and terrain walks): the least
height of the whole sole above the ground under it while the ankle covers 10% to 90% of its forward travel,
against the robot's configured clearance; and the largest share of a swing's time before the sole is
0.2 mm off the ground.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gaitbot.app.progress import progress  # noqa: E402
from gaitbot.gait.swing_clearance import FORWARD_WINDOW, LIFTED_M, MOVES_M, swings  # noqa: E402
from gaitbot.gait.terrain.course_file import load_course  # noqa: E402
from gaitbot.gait.terrain.walk import plan_terrain_walk  # noqa: E402
from gaitbot.gait.walker import make_context, plan_walk, trajectory_of  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config, shipped_config_names  # noqa: E402
from gaitbot.robot.walk_settings import GaitSource, leg_geometry, terrain_settings, walk_settings  # noqa: E402
from gaitbot.gait.planning import steps_for_distance  # noqa: E402

DEFAULT_ROBOT = "xl430-biped"
COURSES = ("kerb", "stairs", "ditch")


def walks(name: str):
    """(what, trajectory, terrain) of a 1 m flat walk and of each example course of robot ``name``."""
    config = load_robot_config(resolve_config(name))
    geometry, settings = leg_geometry(config), walk_settings(config)
    walker = plan_walk(geometry, steps_for_distance(1.0, config.gait.max_step_m), settings)
    yield "flat 1 m", trajectory_of(walker), None
    source = GaitSource(geometry, settings, config.gait.max_step_m, config)
    folder = ROOT / "config" / "terrain" / ("" if name == DEFAULT_ROBOT else name)
    for course_name in COURSES:
        course = load_course(folder / f"{course_name}.toml")
        walk = plan_terrain_walk(make_context(geometry, settings), course.terrain, course.start_m, course.end_m,
                                 terrain_settings(source, course), config.gait.max_step_m)
        yield course_name, walk.trajectory, course.terrain


def measure():
    """The rows of the table, for every shipped robot the planar walker drives (a robot whose legs roll walks
    balanced, its swings checked by tests/gait/test_balance_exact.py)."""
    rows = []
    names = [name for name in shipped_config_names() if not load_robot_config(resolve_config(name)).is_3d]
    with progress("swing clearance", total=len(names) * (1 + len(COURSES)), unit="walk") as bar:
        for name in names:
            config = load_robot_config(resolve_config(name))
            geometry = leg_geometry(config)
            for what, trajectory, terrain in walks(name):
                found = swings(geometry, trajectory, terrain)
                rows.append((name, what, config.gait.clearance_m, len(found), min(s.clearance_m for s in found if s.travel_m > MOVES_M),
                             max(s.lift_off_share for s in found)))
                bar.update(1)
    return rows


def markdown(rows) -> str:
    lines = ["| robot | walk | swings | configured clearance | least clearance while moving forward | "
             "longest near the ground at lift-off |", "|---|---|---|---|---|---|"]
    for name, what, clearance, n, least, share in rows:
        lines.append(f"| {name} | {what} | {n} | {1000 * clearance:.1f} mm | {1000 * least:.1f} mm | "
                     f"{100 * share:.1f}% of the swing |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figures (tools/figures.py)")
    args = parser.parse_args(argv)
    rows = measure()
    if args.markdown:
        print(f"<!-- figure swing-clearance -->\n{markdown(rows)}\n<!-- /figure -->")
        return 0
    print(f"least sole height while the ankle covers {FORWARD_WINDOW[0]:.0%} to {FORWARD_WINDOW[1]:.0%} of its "
          f"travel; longest share of a swing before the sole is {LIFTED_M * 1000:.1f} mm up")
    for name, what, clearance, n, least, share in rows:
        verdict = "ok" if least >= clearance * (1 - 1e-3) else "BELOW THE CLEARANCE"
        print(f"{name:14s} {what:9s} {n:3d} swings: least {1000 * least:5.1f} mm (configured {1000 * clearance:.1f}); "
              f"lift-off {100 * share:4.1f}%  {verdict}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
