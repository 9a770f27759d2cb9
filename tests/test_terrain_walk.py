"""Terrain walks judged from the emitted angles and root alone (own forward kinematics, gait-model.md
section 1): no foot point under the terrain, locked contacts still, footholds on one tread with their
margin, swing clearance over every edge, joint and velocity limits, continuous joint velocities at
every switch between the flat walker and the terrain segments; the grid search against brute force."""

from pathlib import Path

import numpy as np
import pytest

from gaitbot.check import check_trajectory
from gaitbot.cli import main
from gaitbot.gait.terrain.model import Terrain, Tread
from gaitbot.gait.terrain.walk import plan_terrain_walk
from gaitbot.robot.config import default_config_path, load_robot_config
from gaitbot.session import GaitSource, terrain_settings
from gaitbot.robot.gait_setup import leg_geometry, walk_settings
from gaitbot.gait.walker import make_context
from gaitbot.terrain_file import Course, load_course

CONFIG = Path(__file__).resolve().parents[1] / "config" / "terrain"
ROBOT = load_robot_config(default_config_path())
GEOMETRY = leg_geometry(ROBOT)
SOURCE = GaitSource(GEOMETRY, walk_settings(ROBOT), ROBOT.gait.max_step_m, ROBOT)
TOUCH = 1e-9  # a point this close to the terrain in two consecutive frames is a locked contact


def fk_feet(q, root):
    """Heel and toe in the world of one leg from hip, knee, ankle flexion (own FK, section 1)."""
    g = GEOMETRY
    h, k, a = q[:, 0], q[:, 1], q[:, 2]
    ankle = root + np.column_stack([g.thigh * np.sin(h) + g.shank * np.sin(h - k),
                                    -g.thigh * np.cos(h) - g.shank * np.cos(h - k)])
    p = h - k + a  # sole pitch, toe up
    sole = ankle + g.ankle_height * np.column_stack([np.sin(p), -np.cos(p)])
    heel = sole - g.heel_back * np.column_stack([np.cos(p), np.sin(p)])
    toe = heel + g.foot * np.column_stack([np.cos(p), np.sin(p)])
    return heel, toe


def walk_course(course: Course):
    settings = terrain_settings(SOURCE, course)
    walk = plan_terrain_walk(make_context(GEOMETRY, SOURCE.settings), course.terrain, course.start_m, course.end_m,
                             settings, SOURCE.max_step_m)
    return walk, settings


def surface_pieces(treads):
    pieces, x = [], -np.inf
    for t in sorted(treads, key=lambda t: t.start_m):
        if t.start_m > x + 1e-9:
            pieces.append([x, t.start_m, 0.0])
        pieces.append([t.start_m, t.start_m + t.length_m, t.height_m])
        x = t.start_m + t.length_m
    pieces.append([x, np.inf, 0.0])
    merged = []
    for p in pieces:
        if merged and merged[-1][2] == p[2] and abs(merged[-1][1] - p[0]) < 1e-9:
            merged[-1][1] = p[1]
        else:
            merged.append(p)
    return merged


def height(pieces, x):
    """Terrain height under x (at an edge: the higher side), independent of gaitbot's Terrain."""
    out = np.zeros_like(x)
    for i, xi in enumerate(x):
        out[i] = max(h for s, e, h in pieces if s - 1e-12 <= xi <= e + 1e-12)
    return out


def judge(walk, settings, treads):
    traj = walk.trajectory
    pieces = surface_pieces(treads)
    leg = GEOMETRY.leg_length
    report = check_trajectory(ROBOT, traj.t_s, np.degrees(traj.angles_rad))
    assert report.ok, report.first_error
    edges = [(a[1], max(a[2], b[2])) for a, b in zip(pieces, pieces[1:])]
    for side in (0, 1):
        heel, toe = fk_feet(traj.angles_rad[:, 3 * side:3 * side + 3], traj.root_m)
        gap_heel = heel[:, 1] - height(pieces, heel[:, 0])
        gap_toe = toe[:, 1] - height(pieces, toe[:, 0])
        assert min(gap_heel.min(), gap_toe.min()) > -1e-4 * leg, "a foot point under the terrain"
        for point, gap in ((heel, gap_heel), (toe, gap_toe)):
            held = (gap[1:] < TOUCH) & (gap[:-1] < TOUCH)
            moved = np.hypot(*(point[1:] - point[:-1]).T)[held]
            assert moved.max() < 1e-6 * leg, f"a locked contact moves by {moved.max():.2e} m"
        touching = (gap_heel < TOUCH) | (gap_toe < TOUCH)
        for x, top in edges:
            over = (heel[:, 0] < x - 1e-9) & (x + 1e-9 < toe[:, 0]) & ~touching
            if over.any():
                share = (x - heel[over, 0]) / (toe[over, 0] - heel[over, 0])
                sole_y = heel[over, 1] + share * (toe[over, 1] - heel[over, 1])
                assert (sole_y - top).min() >= settings.clearance - 1e-6, f"swing over the edge at x = {x}"
    for strike in traj.heel_strikes:
        on = [p for p in pieces if p[0] + settings.margin - 1e-9 <= strike.x_m
              and strike.x_m + GEOMETRY.foot + settings.margin <= p[1] + 1e-9]
        assert on, f"foothold at {strike.x_m} not on one tread with its margin"
    # continuous joint velocities: at every switch of segment the velocity changes no more than nearby
    vel = np.diff(traj.angles_rad, axis=0) * walk.ctx.rate_hz
    jump = np.abs(np.diff(vel, axis=0)).max(axis=1)
    bounds = np.cumsum([s.n_frames for s in walk.segments])[:-1]
    for b in bounds:
        near = np.r_[jump[max(0, b - 4):b - 2], jump[b + 1:b + 3]]
        assert jump[b - 1] <= 3 * near.max() + np.radians(2.0), f"velocity jump at frame {b}"


@pytest.fixture(scope="module")
def stairs():
    course = load_course(CONFIG / "stairs.toml")
    return course, *walk_course(course)


@pytest.mark.parametrize("name", ["kerb", "ditch"])
def test_examples_walk_cleanly(name):
    course = load_course(CONFIG / f"{name}.toml")
    walk, settings = walk_course(course)
    judge(walk, settings, course.terrain.treads)
    assert any(s.method == "terrain" for s in walk.steps) and any(s.method == "flat" for s in walk.steps)


def test_stairs_walk_cleanly(stairs):
    course, walk, settings = stairs
    judge(walk, settings, course.terrain.treads)
    heights = {round(s.height_m, 6) for s in walk.steps}
    assert heights >= {0.0} | {round(t.height_m, 6) for t in course.terrain.treads}  # every stair is stood on
    # one trajectory from flat ground up and back down to flat ground, ending where it should
    assert walk.trajectory.root_m[-1, 0] == pytest.approx(walk.steps[-1].foothold_m + GEOMETRY.heel_back, abs=1e-6)


@pytest.mark.parametrize("rise, going", [(0.015, 0.16), (-0.03, 0.15), (0.03, 0.18), (0.025, 0.25)])
def test_other_stairs(rise, going):
    treads = tuple(Tread(round(0.35 + i * going, 6), going, round(rise * (i + 1), 6)) for i in range(3)) + (
        Tread(round(0.35 + 3 * going, 6), 0.4, round(3 * rise, 6)),)
    course = Course("hidden.toml", Terrain(treads), 0.0, round(0.35 + 3 * going + 0.2, 6))
    walk, settings = walk_course(course)
    judge(walk, settings, treads)


def test_flat_steps_are_the_boulic_walkers(stairs):
    _, walk, _ = stairs
    flat = [s for s in walk.steps if s.method == "flat"]
    assert len(flat) >= 6  # the flat approaches and exits are the flat walker's steps
    assert sum(s.method == "terrain" for s in walk.steps) >= 6


def test_grid_search_beats_the_middle_and_nears_brute_force(stairs):
    _, walk, _ = stairs
    reports = walk.search_reports
    assert reports and all(r.full_grid == 625 for r in reports)
    assert all(r.cost <= r.centre_cost for r in reports)
    assert any(r.cost < 0.9 * r.centre_cost or not np.isfinite(r.centre_cost) for r in reports)
    for problem in walk.search_problems[:3]:
        fast = problem.search()
        full = problem.brute_force(25)
        assert fast.cost <= 1.05 * full.cost
        assert fast.evaluated <= 50 < full.evaluated + full.pruned


def test_cli_plan_generate_plot(tmp_path, capsys):
    course = str(CONFIG / "kerb.toml")
    assert main(["plan", "--terrain", course]) == 0
    out = capsys.readouterr().out
    assert "of 625 in a full search" in out and "middle of the region" in out
    assert main(["generate", "--terrain", course, "-o", str(tmp_path / "k.npz")]) == 0
    pytest.importorskip("matplotlib")
    assert main(["plot", str(tmp_path / "k.npz"), "--terrain", course, "-o", str(tmp_path / "k.png")]) == 0
    assert (tmp_path / "k.png").stat().st_size > 1000


def test_cli_unwalkable_obstacle_exit_2(tmp_path, capsys):
    wall = tmp_path / "wall.toml"
    wall.write_text("[course]\nstart_m = 0.0\nend_m = 1.0\n[[tread]]\nstart_m = 0.5\nlength_m = 0.05\n"
                    "height_m = 0.15\n")
    assert main(["plan", "--terrain", str(wall)]) == 2
    err = capsys.readouterr().err
    from gaitbot.robot.config import default_config_path, load_robot_config

    max_rise = load_robot_config(default_config_path()).terrain.max_rise_m  # the robot's stated envelope
    assert f"{wall}: tread 1: stands 0.15 m above its neighbours" in err and f"max {max_rise:.4f} m for xl430-biped" in err
    with pytest.raises(SystemExit):
        main(["plan", "--terrain", str(wall), "--steps", "0.1"])
