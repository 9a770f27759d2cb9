"""Foothold planner: each foot fully on one tread with its margin, steps and rises within reach,
and a clear error saying where and why when the course cannot be walked."""

from pathlib import Path

import numpy as np
import pytest

from gaitbot.gait.terrain.footholds import CourseError, FootholdLimits, plan_footholds
from gaitbot.gait.terrain.model import Terrain, Tread
from gaitbot.terrain_file import load_course

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "config" / "terrain").glob("*.toml"))
LIMITS = FootholdLimits(foot=0.12, margin=0.01, flat_max_step=0.10, terrain_max_step=0.165, max_rise=0.055,
                        max_travel=0.165)


def surfaces_from_treads(treads):
    """Independent profile: (start, end, height) pieces including the ground at 0 between treads."""
    pieces, x = [], -np.inf
    for t in sorted(treads, key=lambda t: t.start_m):
        if t.start_m > x + 1e-9:
            pieces.append((x, t.start_m, 0.0))
        pieces.append((t.start_m, t.start_m + t.length_m, t.height_m))
        x = t.start_m + t.length_m
    pieces.append((x, np.inf, 0.0))
    return pieces


def holding_piece(pieces, heel, foot, margin):
    """The piece holding the whole foot with its margin, or None."""
    for start, end, h in pieces:
        if heel - margin >= start - 1e-9 and heel + foot + margin <= end + 1e-9:
            # a zero-height tread next to the ground is the same surface: merge neighbours of equal height
            return start, end, h
    # allow merged equal-height neighbours
    for (s1, e1, h1), (s2, e2, h2) in zip(pieces, pieces[1:]):
        if abs(e1 - s2) < 1e-9 and h1 == h2 and heel - margin >= s1 - 1e-9 and heel + foot + margin <= e2 + 1e-9:
            return s1, e2, h1
    return None


def check_plan(treads, start, end, holds, limits):
    pieces = surfaces_from_treads(treads)
    xs = [start, start] + [h.heel_x for h in holds]
    heights = []
    for x in xs:
        piece = holding_piece(pieces, x, limits.foot, limits.margin)
        assert piece is not None, f"foothold at {x} not on one tread with margin"
        heights.append(piece[2])
    assert xs[-1] >= end - 1e-9
    for k in range(2, len(xs)):
        step = xs[k] - xs[k - 1]
        assert -1e-9 <= step <= limits.terrain_max_step + 1e-9
        if heights[k] == heights[k - 1] and step > limits.flat_max_step + 1e-9:
            # a long step on one level is allowed only across an edge (a ditch)
            assert any(xs[k - 1] < p[0] < xs[k] + limits.foot for p in pieces[1:])
        one_level = heights[k] == heights[k - 1] == heights[k - 2]
        assert xs[k] - xs[k - 2] <= (2 * limits.flat_max_step if one_level else limits.max_travel) + 1e-9
        assert abs(heights[k] - heights[k - 1]) <= limits.max_rise + 1e-9


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_examples(path):
    course = load_course(path)
    holds = plan_footholds(course.terrain, course.start_m, course.end_m, LIMITS)
    check_plan(course.terrain.treads, course.start_m, course.end_m, holds, LIMITS)
    for h in holds:
        assert h.height == pytest.approx(float(course.terrain.height_at(h.heel_x + LIMITS.foot / 2)))


@pytest.mark.parametrize("rise, going, n", [(0.02, 0.15, 4), (0.035, 0.16, 6), (0.05, 0.2, 3), (-0.03, 0.15, 5)])
def test_stairs_of_several_rises_and_goings(rise, going, n):
    treads = [Tread(0.3 + i * going, going, rise * (i + 1)) for i in range(n)]
    treads.append(Tread(0.3 + n * going, 0.5, rise * n))
    holds = plan_footholds(Terrain(tuple(treads)), 0.0, 0.3 + n * going + 0.2, LIMITS)
    check_plan(treads, 0.0, 0.3 + n * going + 0.2, holds, LIMITS)
    on_each = {round(h.height, 6) for h in holds}
    assert all(round(rise * (i + 1), 6) in on_each for i in range(n)), "every stair is stepped on"


def test_flat_course_takes_the_fewest_steps():
    holds = plan_footholds(Terrain(()), 0.0, 1.0, LIMITS)
    assert len(holds) == 10 and holds[-1].heel_x == pytest.approx(1.0)


def test_margin_is_kept_and_can_fail():
    treads = [Tread(0.3, 0.15, 0.02), Tread(0.45, 0.5, 0.04)]
    holds = plan_footholds(Terrain(tuple(treads)), 0.0, 0.8, LIMITS)
    check_plan(treads, 0.0, 0.8, holds, LIMITS)
    # a tread 0.13 m long cannot hold a 0.12 m foot with 0.01 m margins at both ends
    short = (Tread(0.3, 0.13, 0.03), Tread(0.43, 0.5, 0.06))
    with pytest.raises(CourseError) as err:
        plan_footholds(Terrain(short), 0.0, 0.8, LIMITS)
    assert "cannot walk past x = " in str(err.value)


@pytest.mark.parametrize("treads, why", [
    ((Tread(0.4, 1.0, 0.12),), "rise of 0.120 m"),
    ((Tread(0.4, 0.05, 0.2),), "stands 0.200 m above"),
    ((Tread(0.4, 0.1, -0.3),), "longer than the longest step"),
])
def test_unwalkable_says_where_and_why(treads, why):
    with pytest.raises(CourseError) as err:
        plan_footholds(Terrain(treads), 0.0, 1.2, LIMITS)
    message = str(err.value)
    assert "cannot walk past x = 0.2" in message, message
    assert why in message, message


def test_start_off_a_tread_is_an_error():
    with pytest.raises(CourseError, match="course.start_m"):
        plan_footholds(Terrain((Tread(0.0, 0.1, 0.03),)), 0.0, 1.0, LIMITS)
