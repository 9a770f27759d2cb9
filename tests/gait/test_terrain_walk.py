"""Terrain walks judged from the emitted angles and root alone (own forward kinematics, docs/gait-model.md
section 1, and an own terrain profile built from the treads): no foot point under the terrain, locked
contacts still, footholds on one tread with their margin, swing clearance over every edge, joint
position, velocity and acceleration limits, continuous joint velocities at every switch between the
flat walker and the terrain segments, a pelvis that never turns back while walking forward. Courses:
the shipped examples and a sweep of stairs, kerbs and ditches inside every shipped robot's stated
envelope (its config's [terrain] table), like the hidden courses the issue promises."""

from pathlib import Path

import numpy as np
import pytest

from gaitbot.check.trajectory import check_trajectory
from gaitbot.app.cli import main
from gaitbot.gait.terrain.model import Terrain, Tread
from gaitbot.gait.terrain.swing import warp_table
from gaitbot.gait.terrain.walk import plan_terrain_walk
from gaitbot.gait.walker import make_context
from gaitbot.robot.config import load_robot_config
from gaitbot.robot.walk_settings import leg_geometry, walk_settings
from gaitbot.robot.walk_settings import GaitSource, terrain_settings
from gaitbot.gait.terrain.course_file import Course, load_course
from helpers import REPO_ROOT, fk_foot, height, surface_pieces, swing_clearances

ROOT = REPO_ROOT
EXAMPLES = ROOT / "config" / "terrain"
# Terrain is walked by the planar walker: every shipped pitch-only robot, each of which states its step
# envelope ([terrain], tests/gait/test_terrain_envelope.py). A robot whose legs roll walks balanced, on the flat only.
ROBOTS = sorted(p.stem for p in (ROOT / "config").glob("*.toml") if not load_robot_config(p).is_3d)
TOUCH = 1e-9  # a point this close to the terrain in two consecutive frames is a locked contact
MARGIN = 0.01
LIFT_OFF_SHARE = 0.05  # the most of a swing's time its sole may stay within 0.2 mm of the ground at lift-off


class Robot:
    def __init__(self, name: str) -> None:
        self.config = load_robot_config(ROOT / "config" / f"{name}.toml")
        self.geometry = leg_geometry(self.config)
        self.source = GaitSource(self.geometry, walk_settings(self.config), self.config.gait.max_step_m, self.config)
        self.ctx = make_context(self.geometry, self.source.settings)
        reach = self.config.terrain
        self.rise, self.drop, self.gap = reach.max_rise_m, reach.max_drop_m, reach.max_gap_m
        self.min_going = self.config.geometry.foot_m + 2 * MARGIN

    def walk(self, course: Course):
        settings = terrain_settings(self.source, course)
        walk = plan_terrain_walk(self.ctx, course.terrain, course.start_m, course.end_m, settings,
                                 self.source.max_step_m)
        return walk, settings


_ROBOTS: dict[str, Robot] = {}


def robot(name: str) -> Robot:
    if name not in _ROBOTS:
        _ROBOTS[name] = Robot(name)
    return _ROBOTS[name]


def fk_feet(cfg, q, root):
    return fk_foot(cfg, q, root)[1:]


def judge(rb: Robot, walk, settings, treads):
    traj = walk.trajectory
    cfg = rb.config
    pieces = surface_pieces(treads)
    leg = cfg.geometry.thigh_m + cfg.geometry.shank_m
    report = check_trajectory(cfg, traj.t_s, np.degrees(traj.angles_rad))
    assert report.ok, report.first_error
    edges = [(a[1], max(a[2], b[2])) for a, b in zip(pieces, pieces[1:])]
    for side in (0, 1):
        heel, toe = fk_feet(cfg, traj.angles_rad[:, 3 * side:3 * side + 3], traj.root_xz_m)
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
              and strike.x_m + cfg.geometry.foot_m + settings.margin <= p[1] + 1e-9]
        assert on, f"foothold at {strike.x_m} not on one tread with its margin"
    # every swing keeps the clearance while its foot moves forward, and leaves the ground at once (docs/gait.md)
    for travel, least, lift_off in swing_clearances(cfg, traj, treads):
        assert least >= settings.clearance * (1 - 1e-3), f"a swing of {travel:.3f} m lifts only {least * 1000:.1f} mm"
        assert lift_off <= LIFT_OFF_SHARE, f"a swing of {travel:.3f} m stays on the ground for {lift_off:.0%} of it"
    # continuous joint velocities: at every switch of segment the velocity changes no more than nearby
    vel = np.diff(traj.angles_rad, axis=0) * walk.ctx.rate_hz
    jump = np.abs(np.diff(vel, axis=0)).max(axis=1)
    bounds = np.cumsum([s.n_frames for s in walk.segments])[:-1]
    for b in bounds:
        near = np.r_[jump[max(0, b - 4):b - 2], jump[b + 1:b + 3]]
        assert jump[b - 1] <= 3 * near.max() + np.radians(2.0), f"velocity jump at frame {b}"
    # the pelvis never turns back while walking forward: from the first heel strike to the closing step
    t, x = traj.t_s, traj.root_m[:, 0]
    walking = (t[1:] >= traj.heel_strikes[0].t_s) & (t[1:] <= traj.heel_strikes[-2].t_s)
    assert np.diff(x)[walking].min() >= -1e-9, "the pelvis moves backward (a loop in its path)"


def stairs(rise, going, n=3, down_again=False):
    """n stairs, a landing, and either n - 1 stairs back down and the ground, or the end on the landing."""
    treads = [Tread(round(0.3 + i * going, 6), round(going, 6), round(rise * (i + 1), 6)) for i in range(n)]
    x = round(0.3 + n * going, 6)
    if not down_again:
        treads.append(Tread(x, 0.6, round(rise * n, 6)))
        return tuple(treads), round(x + 0.25, 6)
    treads.append(Tread(x, 0.3, round(rise * n, 6)))
    x = round(x + 0.3, 6)
    for i in range(n - 1):
        treads.append(Tread(round(x + i * going, 6), round(going, 6), round(rise * (n - 1 - i), 6)))
    return tuple(treads), round(x + (n - 1) * going + 0.15, 6)


def ditch(width):
    return (Tread(0.35, width, -0.05),), 0.35 + width + 0.3


def kerb(rise):
    return (Tread(0.35, 0.8, rise),), 0.75


def sweep(name):
    rb = robot(name)
    g = rb.min_going
    return {
        "up at the largest rise, shortest going": stairs(rb.rise, g),
        "up at the largest rise, long going": stairs(rb.rise, 1.7 * g),
        "down at the largest drop, shortest going": stairs(-rb.drop, g),
        "down at the largest drop, long going": stairs(-rb.drop, 2.1 * g),
        "up and down, half the rise": stairs(0.5 * min(rb.rise, rb.drop), 1.2 * g, down_again=True),
        "kerb at the largest rise": kerb(rb.rise),
        "ditch at the widest gap": ditch(rb.gap),
    }


#: Two of the default robot's courses (a rise at the edge of its envelope) run in the quick loop; the rest of
#: its sweep and the other robots' (each robot's stated envelope figures walked again, a minute on two cores)
#: in the slow set, which the full run and CI include.
QUICK_ROBOT = "xl430-biped"
QUICK_CASES = ("kerb at the largest rise", "up at the largest rise, shortest going")
CASES = [pytest.param(name, case, id=f"{name}: {case}",
                      marks=[] if name == QUICK_ROBOT and case in QUICK_CASES else [pytest.mark.slow])
         for name in ROBOTS for case in sweep(name)]


@pytest.mark.parametrize("name, case", CASES)
def test_courses_inside_the_envelope_walk_cleanly(name, case):
    rb = robot(name)
    treads, end = sweep(name)[case]
    walk, settings = rb.walk(Course(case, Terrain(treads), 0.0, end))
    judge(rb, walk, settings, treads)
    assert any(s.method == "terrain" for s in walk.steps) and any(s.method == "flat" for s in walk.steps)


def examples_for(name: str) -> Path:
    """The examples made for a robot: config/terrain/ for the default one, config/terrain/<robot>/ else."""
    return EXAMPLES if name == "xl430-biped" else EXAMPLES / name


_EXAMPLE_WALKS: dict[tuple[str, str], tuple] = {}


def example_walk(name: str, example: str):
    """(course, walk, settings) of a shipped example course on a robot, planned once per test process: the
    default robot's stairs are judged below and examined by the tests of ``stairs_walk`` (one xdist group)."""
    key = (name, example)
    if key not in _EXAMPLE_WALKS:
        course = load_course(examples_for(name) / f"{example}.toml")
        _EXAMPLE_WALKS[key] = (course, *robot(name).walk(course))
    return _EXAMPLE_WALKS[key]


def _grouped(name: str, example: str):
    """The default robot's stairs run on the worker of the ``stairs_walk`` tests, which reuse its walk; the
    default robot's kerb and ditch are the quick loop's, the stairs (seconds of planning) and the other
    robots' examples are slow."""
    marks = [pytest.mark.xdist_group("stairs-xl430")] if (name, example) == ("xl430-biped", "stairs") else []
    marks += [] if name == QUICK_ROBOT and example != "stairs" else [pytest.mark.slow]
    return pytest.param(name, example, marks=marks, id=f"{example}-{name}")


@pytest.mark.parametrize("name, example", [_grouped(n, e) for e in ("kerb", "stairs", "ditch") for n in ROBOTS])
def test_examples_walk_cleanly_on_every_robot(name, example):
    course, walk, settings = example_walk(name, example)
    judge(robot(name), walk, settings, course.terrain.treads)


@pytest.mark.parametrize("name", ROBOTS)
def test_examples_are_meaningful_for_their_robot(name):
    rb = robot(name)
    where = examples_for(name)
    kerb_ = load_course(where / "kerb.toml").terrain.treads
    stairs_ = load_course(where / "stairs.toml").terrain.treads
    ditch_ = load_course(where / "ditch.toml").terrain.treads
    assert max(t.height_m for t in kerb_) >= 0.75 * rb.rise
    rises = np.diff([0.0] + [t.height_m for t in sorted(stairs_, key=lambda t: t.start_m)] + [0.0])
    assert (rises > 1e-9).sum() >= 3 and (rises < -1e-9).sum() >= 3
    assert np.abs(rises).max() >= 0.75 * min(rb.rise, rb.drop)
    width = max(t.length_m for t in ditch_ if t.height_m < 0)
    assert width >= 0.5 * rb.gap and width > 0.3 * rb.geometry.foot  # a real step over, not a crack


@pytest.fixture(scope="module")
def stairs_walk():
    return example_walk("xl430-biped", "stairs")  # examples_for("xl430-biped") is EXAMPLES


@pytest.mark.slow
@pytest.mark.xdist_group("stairs-xl430")
def test_stairs_up_and_down_are_one_walk(stairs_walk):
    course, walk, _ = stairs_walk
    heights = [s.height_m for s in walk.steps]
    assert heights[0] == 0.0 and heights[-1] == 0.0 and max(heights) == max(t.height_m for t in course.terrain.treads)
    rb = robot("xl430-biped")
    assert walk.trajectory.root_m[-1, 0] == pytest.approx(walk.steps[-1].foothold_m + rb.geometry.heel_back, abs=1e-6)


@pytest.mark.slow
@pytest.mark.xdist_group("stairs-xl430")
def test_flat_steps_are_the_boulic_walkers(stairs_walk):
    _, walk, _ = stairs_walk
    flat = [s for s in walk.steps if s.method == "flat"]
    assert len(flat) >= 4  # the flat approaches and exits are the flat walker's steps
    assert sum(s.method == "terrain" for s in walk.steps) >= 6
    inner = [type(getattr(s, "inner", s)).__name__ for s in walk.segments]
    assert inner.count("StepSegment") == len(flat)


@pytest.mark.slow
@pytest.mark.xdist_group("stairs-xl430")
def test_grid_search_beats_the_middle_and_nears_brute_force(stairs_walk):
    _, walk, _ = stairs_walk
    reports = walk.search_reports
    assert reports and all(r.full_grid == 625 for r in reports)
    assert all(r.cost <= r.centre_cost for r in reports)
    assert sum(r.evaluated for r in reports) < 0.1 * sum(r.full_grid for r in reports)
    for problem in walk.search_problems[:2]:
        fast = problem.search()
        full = problem.brute_force(25)
        assert fast.cost <= 1.05 * full.cost
        assert fast.evaluated <= 75 < full.evaluated + full.pruned


@pytest.mark.slow
@pytest.mark.xdist_group("stairs-xl430")
def test_a_level_of_cells_scores_as_each_cell_alone(stairs_walk):
    """The search scores a level's cells in one batch (the swing's tip fitted for all their pelvis paths at
    once); each cell's cost must be exactly what it scores alone, feasible or not, on every MDS point."""
    _, walk, _ = stairs_walk
    rng = np.random.default_rng(3)
    for problem in walk.search_problems:
        x0, x1, y0, y1 = problem.region
        points = np.column_stack([rng.uniform(x0, x1, 12), rng.uniform(y0, y1, 12)])
        together = problem.cost(points)
        alone = np.array([problem.cost(p[None])[0] for p in points])
        np.testing.assert_array_equal(together, alone)
        np.testing.assert_array_equal(problem.reachable(points), [problem.reachable(p[None])[0] for p in points])


@pytest.mark.slow
@pytest.mark.xdist_group("stairs-xl430")
def test_swing_feet_fitted_together_are_each_as_fitted_alone(stairs_walk):
    """The swing's sole, tipped and lifted for many hip paths in one batch (a path's timings settle their
    lift together, paths apart), is exactly what each path gets alone. Hips lowered 0 to 3 cm below the
    walk's bend the knee until the sole must tip and lift: some paths need no lift, some several rounds."""
    _, walk, _ = stairs_walk
    steps = [s for s in (getattr(seg, "inner", seg) for seg in walk.segments) if hasattr(s, "swing_times")]
    s, sigma = np.linspace(0.0, 1.0, 31), warp_table(1.0, 31)
    lifted = 0
    for step in steps:
        hips = step.pelvis(step.swing_times(1.0, 31))
        paths = np.stack([hips - [0.0, drop] for drop in np.linspace(0.0, 0.03, 7)])
        rows = np.broadcast_to(paths[:, None], (len(paths), len(sigma), len(s), 2))
        poses, lift = step.swing.fitted(s, sigma, rows, paths=len(paths))
        for k, hip in enumerate(rows):
            alone = step.swing.fitted(s, sigma, hip)
            np.testing.assert_array_equal(poses[k * len(sigma):(k + 1) * len(sigma)], alone[0])
            np.testing.assert_array_equal(lift[k * len(sigma):(k + 1) * len(sigma)], alone[1])
        lifted += len({round(x, 9) for x in lift.reshape(len(paths), -1).max(axis=1)}) > 2
    assert lifted >= 2  # the batches did hold paths that settle their lift in different rounds


def test_cli_plan_generate_plot(tmp_path, capsys):
    course = str(EXAMPLES / "kerb.toml")
    assert main(["plan", "--terrain", course]) == 0
    out = capsys.readouterr().out
    assert "of 625 in a full search" in out and "middle of the region" in out
    assert main(["generate", "--terrain", course, "-o", str(tmp_path / "k.npz")]) == 0
    pytest.importorskip("matplotlib")
    assert main(["plot", str(tmp_path / "k.npz"), "--terrain", course, "-o", str(tmp_path / "k.png")]) == 0
    assert (tmp_path / "k.png").stat().st_size > 1000


@pytest.mark.parametrize("body, where, why", [
    ("start_m = 0.5\nlength_m = 0.05\nheight_m = 0.15\n", "tread 1", "stands 0.15 m above its neighbours"),
    ("start_m = 0.5\nlength_m = 0.6\nheight_m = 0.07\n", "tread 1", "rise 0.07 m exceeds what this leg can step "
                                                                    "(max 0.0375 m for xl430-biped)"),  # its [terrain] max_rise_m
    ("start_m = 0.5\nlength_m = 0.6\nheight_m = -0.06\n", "tread 1", "drop 0.06 m exceeds"),
    ("start_m = 0.5\nlength_m = 0.12\nheight_m = -0.2\n", "the ground after tread 1", "a gap of 0.12 m"),
    ("start_m = 0.5\nlength_m = 0.13\nheight_m = 0.03\n[[tread]]\nstart_m = 0.63\nlength_m = 0.5\nheight_m = 0.06\n",
     "tread 2", "tread 1 before it is too short to stand on"),
])
def test_cli_unwalkable_obstacle_exit_2(tmp_path, capsys, body, where, why):
    path = tmp_path / "course.toml"
    path.write_text("[course]\nstart_m = 0.0\nend_m = 1.2\n[[tread]]\n" + body)
    assert main(["plan", "--terrain", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(f"gaitbot plan: error: {path}: {where}: "), err
    assert why in err, err
    with pytest.raises(SystemExit):
        main(["plan", "--terrain", str(path), "--steps", "0.1"])
