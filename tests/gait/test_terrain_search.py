"""Seed 003's pelvis Bezier segments and the two-level 5 x 5 grid search."""

import numpy as np
import pytest

from gaitbot.gait.terrain.pelvis import Knot, PelvisPath, bernstein, bezier
from gaitbot.gait.terrain.search import brute_force, cell_centres, two_level_search

REGION = (0.0, 1.0, -0.5, 0.5)


def test_bernstein_partition_of_unity_and_bezier_ends():
    s = np.linspace(0, 1, 11)
    assert np.allclose(bernstein(3, s).sum(axis=1), 1.0)
    control = np.array([[0.0, 0.0], [1.0, 2.0], [2.0, -1.0], [3.0, 0.5]])
    pts = bezier(control, [0.0, 1.0])
    assert np.allclose(pts, control[[0, 3]])


def test_pelvis_path_passes_knots_with_their_velocities():
    knots = [Knot(0.0, (0.0, 0.20), (0.1, 0.05), "start"), Knot(0.3, (0.05, 0.18), (0.12, 0.0), "MDS"),
             Knot(1.0, (0.13, 0.21), (0.09, 0.0), "MS"), Knot(1.4, (0.17, 0.19), (0.1, 0.0), "end")]
    path = PelvisPath(knots)
    for k in knots:
        assert np.allclose(path(k.t)[0], k.pos)
        assert np.allclose(path.velocity(k.t)[0], k.vel)
    # C1: one-sided finite differences agree at interior knots
    h = 1e-6
    for k in knots[1:-1]:
        left = (path(k.t)[0] - path(k.t - h)[0]) / h
        right = (path(k.t + h)[0] - path(k.t)[0]) / h
        assert np.allclose(left, right, atol=1e-4)
    # MS and MDS are extremes of height: zero vertical velocity there
    assert path.velocity(0.3)[0, 1] == pytest.approx(0.0) and path.velocity(1.0)[0, 1] == pytest.approx(0.0)


def test_cell_centres():
    c = cell_centres(REGION, 5)
    assert len(c) == 25 and c[:, 0].min() == pytest.approx(0.1) and c[:, 1].max() == pytest.approx(0.4)


def bowl(centre, scale=(1.0, 3.0)):
    return lambda p: 1.0 + scale[0] * (p[:, 0] - centre[0]) ** 2 + scale[1] * (p[:, 1] - centre[1]) ** 2


def everywhere(points):
    return np.ones(len(points), bool)


def nowhere(points):
    return np.zeros(len(points), bool)


@pytest.mark.parametrize("centre", [(0.13, 0.21), (0.77, -0.33), (0.5, 0.0), (0.05, 0.45)])
def test_two_level_search_close_to_brute_force_with_far_fewer_cells(centre):
    cost = bowl(centre)
    fast = two_level_search(REGION, cost, everywhere)
    full = brute_force(REGION, cost, everywhere, n=25)
    assert fast.full_grid == 625 and full.evaluated == 625
    assert 50 <= fast.evaluated <= 75
    assert fast.cost <= 1.05 * full.cost
    assert np.hypot(fast.point[0] - centre[0], fast.point[1] - centre[1]) < 0.05


def test_beats_the_middle_of_the_region():
    result = two_level_search(REGION, bowl((0.2, -0.3)), everywhere)
    assert result.cost < result.centre_cost


def test_unreachable_cells_are_skipped_not_scored():
    scored = []

    def cost(points):
        scored.extend(map(tuple, points))
        return 1.0 + (points[:, 0] - 0.8) ** 2

    reachable = lambda p: p[:, 1] < 0.0  # noqa: E731  upper half out of reach
    result = two_level_search(REGION, cost, reachable)
    assert result.pruned >= 10 and result.evaluated < 75
    assert all(y < 0.0 for _, y in scored)
    assert result.point[1] < 0.0


def test_nothing_reachable_gives_inf():
    result = two_level_search(REGION, bowl((0.5, 0.0)), nowhere)
    assert not np.isfinite(result.cost) and result.evaluated == 0 and result.pruned == 25


def test_an_optimum_across_the_edge_of_the_best_cell_is_followed():
    """The best point presses against the edge of the feasible part (x < 0.63), in a first-level cell whose
    centre (x = 0.7) is infeasible: the second level follows it across the edge of the best cell."""
    def cost(p):
        return np.where(p[:, 0] < 0.63, 1.0 + 3.0 * (0.5 - p[:, 1]) + 5.0 * (0.63 - p[:, 0]), np.inf)

    full = brute_force(REGION, cost, everywhere, n=25)
    plain = two_level_search(REGION, cost, everywhere, follow=0)
    fast = two_level_search(REGION, cost, everywhere)
    assert plain.cost > 1.05 * full.cost  # a centre-only second level stays in the wrong cell
    assert fast.cost <= 1.05 * full.cost and fast.evaluated <= 75
