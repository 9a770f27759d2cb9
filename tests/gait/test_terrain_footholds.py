"""Foothold planner: each foot fully on one tread with its margin, steps and swings within the leg's
envelope, and a clear error saying where and why when the course cannot be walked."""


import numpy as np
import pytest

from gaitbot.gait.terrain.envelope import StepEnvelope
from gaitbot.gait.terrain.footholds import CourseError, FootholdLimits, plan_footholds
from gaitbot.gait.terrain.model import Terrain, Tread
from gaitbot.gait.terrain.course_file import load_course
from helpers import CONFIG_DIR, surface_pieces

EXAMPLES = sorted((CONFIG_DIR / "terrain").glob("*.toml"))
FOOT, MARGIN, FLAT = 0.12, 0.01, 0.10
RISE, DROP, GAP = 0.045, 0.04, 0.08
LIMITS = FootholdLimits(FOOT, MARGIN, FLAT, StepEnvelope.for_foot(FOOT, RISE, DROP, GAP, "test leg"))


def step_limit(rise):
    """Independent restatement of the envelope: FOOT + 2 cm + GAP on the level, down to FOOT + 2 cm at the
    largest rise or drop along (1 - rise / largest)^2, nothing beyond."""
    top = RISE if rise > 0 else DROP
    if abs(rise) > top + 1e-12:
        return -1.0
    return FOOT + 0.02 + GAP * (1 - abs(rise) / top) ** 2


def holding_piece(pieces, heel, foot, margin):
    """Index of the piece holding the whole foot with its margin, or None."""
    for i, (start, end, _) in enumerate(pieces):
        if heel - margin >= start - 1e-9 and heel + foot + margin <= end + 1e-9:
            return i
    return None


def check_plan(treads, start, end, holds):
    pieces = surface_pieces(treads)
    xs = [start, start] + [h.heel_x for h in holds]
    idx = []
    for x in xs:
        i = holding_piece(pieces, x, FOOT, MARGIN)
        assert i is not None, f"foothold at {x} not on one tread with margin"
        idx.append(i)
    assert xs[-1] >= end - 1e-9
    for k in range(2, len(xs)):
        step, travel = xs[k] - xs[k - 1], xs[k] - xs[k - 2]
        assert step >= -1e-9
        if idx[k] == idx[k - 1] == idx[k - 2]:
            assert step <= FLAT + 1e-9 and travel <= 2 * FLAT + 1e-9
        else:
            h = [pieces[i][2] for i in (idx[k - 2], idx[k - 1], idx[k])]
            assert step <= step_limit(h[2] - h[1]) + 1e-9, (xs[k - 1], xs[k])
            assert travel <= step_limit(h[2] - h[0]) + 1e-9, (xs[k - 2], xs[k])
            lo, hi = sorted((idx[k - 2], idx[k]))
            between = [p[2] for p in pieces[lo + 1:hi]]
            assert not between or max(between) - max(h[0], h[2]) <= RISE + 1e-9


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_examples(path):
    course = load_course(path)
    holds = plan_footholds(course.terrain, course.start_m, course.end_m, LIMITS)
    check_plan(course.terrain.treads, course.start_m, course.end_m, holds)
    for h in holds:
        assert h.height == pytest.approx(float(course.terrain.height_at(h.heel_x + FOOT / 2)))


@pytest.mark.parametrize("rise, going, n", [(0.02, 0.15, 4), (0.035, 0.16, 6), (0.045, 0.14, 3), (-0.04, 0.14, 5),
                                            (0.045, 0.31, 3), (-0.03, 0.2, 4)])
def test_stairs_of_several_rises_and_goings(rise, going, n):
    treads = [Tread(0.3 + i * going, going, rise * (i + 1)) for i in range(n)]
    treads.append(Tread(0.3 + n * going, 0.5, rise * n))
    holds = plan_footholds(Terrain(tuple(treads)), 0.0, 0.3 + n * going + 0.2, LIMITS)
    check_plan(treads, 0.0, 0.3 + n * going + 0.2, holds)
    on_each = {round(h.height, 6) for h in holds}
    assert all(round(rise * (i + 1), 6) in on_each for i in range(n)), "every stair is stepped on"


def test_a_tread_barely_longer_than_a_foot_off_the_grid_is_found():
    # admissible heels on tread 1 only from 0.3471 to 0.3491 m: no point of a 5 mm lattice from 0
    treads = (Tread(0.3371, 0.142, 0.03), Tread(0.4791, 0.5, 0.06))
    holds = plan_footholds(Terrain(treads), 0.0, 0.8, LIMITS)
    check_plan(treads, 0.0, 0.8, holds)
    assert any(0.3471 - 1e-9 <= h.heel_x <= 0.3491 + 1e-9 for h in holds)


def test_flat_course_takes_the_fewest_steps():
    holds = plan_footholds(Terrain(()), 0.0, 1.0, LIMITS)
    assert len(holds) == 10 and holds[-1].heel_x == pytest.approx(1.0)


def test_a_ditch_is_stepped_over_in_one_step():
    treads = (Tread(0.4, 0.07, -0.05),)
    holds = plan_footholds(Terrain(treads), 0.0, 0.9, LIMITS)
    check_plan(treads, 0.0, 0.9, holds)
    assert all(not (0.4 - FOOT - MARGIN < h.heel_x < 0.47 + MARGIN) for h in holds)


@pytest.mark.parametrize("treads, where, why", [
    ((Tread(0.4, 1.0, 0.05),), "tread 1", "rise 0.05 m exceeds what this leg can step (max 0.045 m for test leg)"),
    ((Tread(0.4, 1.0, -0.05),), "tread 1", "drop 0.05 m exceeds"),
    ((Tread(0.4, 0.05, 0.06),), "tread 1", "stands 0.06 m above its neighbours"),
    ((Tread(0.4, 0.1, -0.3),), "the ground after tread 1", "a gap of 0.1 m"),
    ((Tread(0.4, 0.04, -0.1), Tread(0.44, 0.6, 0.03)), "tread 2", "a gap of 0.04 m to step over at a rise of +0.03"),
    ((Tread(0.3, 0.13, 0.03), Tread(0.43, 0.5, 0.05)), "tread 2", "rise 0.05 m"),
])
def test_unwalkable_says_where_and_why(treads, where, why):
    with pytest.raises(CourseError) as err:
        plan_footholds(Terrain(treads), 0.0, 1.2, LIMITS)
    message = str(err.value)
    assert message.startswith(f"{where}: "), message
    assert why in message, message


def test_inside_the_envelope_always_plans():
    """Every pair of neighbouring treads within the envelope: the planner finds a plan (step-to if need be)."""
    rng = np.random.default_rng(5)
    for _ in range(25):
        x, h, treads = 0.3, 0.0, []
        for _ in range(4):
            h += float(rng.uniform(-DROP, RISE))
            going = float(rng.uniform(FOOT + 0.02, 0.3))
            treads.append(Tread(round(x, 4), round(going, 4), round(h, 4)))
            x = round(x, 4) + round(going, 4)
        treads.append(Tread(round(x, 4), 0.4, round(h, 4)))
        holds = plan_footholds(Terrain(tuple(treads)), 0.0, x + 0.2, LIMITS)
        check_plan(treads, 0.0, x + 0.2, holds)


def test_start_off_a_tread_is_an_error():
    with pytest.raises(CourseError, match="course.start_m"):
        plan_footholds(Terrain((Tread(0.0, 0.1, 0.03),)), 0.0, 1.0, LIMITS)
